#!/usr/bin/env python3
"""dark-square-lander: a landing system in plain Python 3 (standard library
and numpy), run by touchdown as its own process:

    landing_scenario campaign --system "exec:python3 examples/python_system/dark_square_lander.py"

It speaks touchdown's system protocol, version 1 (docs/formats.md, "System
protocol"), on stdin/stdout: one header line per message, `VERB N1 N2 ...`,
then payloads of exactly those byte counts. Its perception is deliberately
naive, as a first prototype's might be: the marker is "the dark pixels" of
the grey image (a threshold), their centroid projected to the ground through
the pinhole camera. It flies to the GPS target at 8 m, follows the centroid,
starts the descent after 2 s of sightings and lands below 1.5 m. It never
searches, and anything dark (a look-alike marker, a shadow, a dark object)
pulls its estimate: weaknesses a search should find.
"""
import json
import sys

import numpy as np

PROTOCOL = 1
stdin = sys.stdin.buffer
stdout = sys.stdout.buffer


def read_header():
    line = stdin.readline()
    if not line:
        sys.exit(0)  # the host closed the connection
    words = line.decode("ascii").split()
    return words[0], [int(w) for w in words[1:]]


def read(n):
    data = stdin.read(n)
    if len(data) != n:
        sys.exit(0)
    return data


def send(verb, payload=None):
    if payload is None:
        stdout.write((verb + "\n").encode("ascii"))
    else:
        stdout.write(("%s %d\n" % (verb, len(payload))).encode("ascii") + payload)
    stdout.flush()


class DarkSquareLander:
    def reset(self, setup):
        cam = setup["camera"]
        self.width, self.height = cam["width"], cam["height"]
        fx = cam["fx"]
        K = np.array([[fx, 0, self.width / 2], [0, fx, self.height / 2], [0, 0, 1.0]])
        self.K_inv = np.linalg.inv(K)
        self.T_body_camera = np.array(cam["T_body_camera"])
        self.gps = np.array(setup["gps_target"], dtype=float)
        self.estimate = None
        self.seen_since = None
        self.last_seen = -1e9
        self.descending = False

    def look(self, state, image):
        grey = image[:, :, 0] * 0.114 + image[:, :, 1] * 0.587 + image[:, :, 2] * 0.299
        dark = grey < 50
        count = int(dark.sum())
        if count < 30:
            return None
        vs, us = np.nonzero(dark)
        u, v = float(us.mean()), float(vs.mean())
        T_world_camera = np.array(state["T_world_body"]) @ self.T_body_camera
        ray = T_world_camera[:3, :3] @ (self.K_inv @ np.array([u, v, 1.0]))
        origin = T_world_camera[:3, 3]
        if ray[2] >= -1e-9:
            return None
        ground = origin - origin[2] / ray[2] * ray
        box = [float(us.min()), float(vs.min()), float(us.max()), float(vs.max())]
        return ground[:2], box

    def update(self, state, image):
        t = state["t"]
        position = np.array(state["position"])
        answer = {"detections": []}
        if image is not None:
            seen = self.look(state, image)
            if seen is not None:
                ground, (u0, v0, u1, v1) = seen
                self.estimate = ground if self.estimate is None else 0.5 * (self.estimate + ground)
                if self.seen_since is None:
                    self.seen_since = t
                self.last_seen = t
                answer["detections"].append({
                    "id": -1, "corners": [[u0, v0], [u1, v0], [u1, v1], [u0, v1]],
                    "quality": u1 - u0, "confidence": 1.0, "accepted": True,
                    "ground": [float(ground[0]), float(ground[1])]})
        if t - self.last_seen > 1.0:
            self.seen_since = None
        if not self.descending and self.seen_since is not None and t - self.seen_since >= 2.0:
            self.descending = True
            answer["descent_started"] = True
            answer["target"] = [float(self.estimate[0]), float(self.estimate[1])]
        goal = self.estimate if self.estimate is not None else self.gps
        v = goal - position[:2]
        speed = float(np.hypot(v[0], v[1]))
        if speed > 2.5:
            v *= 2.5 / speed
        vz = -0.8 if self.descending else float(np.clip(8.0 - position[2], -1.0, 1.0))
        answer["velocity"] = [float(v[0]), float(v[1]), vz]
        answer["land"] = bool(self.descending and position[2] < 1.5)
        answer["phase"] = "descend" if self.descending else ("follow" if self.estimate is not None else "approach")
        return answer


def main():
    verb, sizes = read_header()
    if verb != "touchdown-system" or sizes != [PROTOCOL]:
        sys.stderr.write("dark_square_lander: the host speaks %s %s, not protocol 1\n" % (verb, sizes))
        return 1
    hello = json.dumps({"name": "dark-square-lander", "wants": ["image"]}).encode()
    stdout.write(b"touchdown-system %d %d\n" % (PROTOCOL, len(hello)) + hello)
    stdout.flush()
    system = DarkSquareLander()
    while True:
        verb, sizes = read_header()
        if verb == "bye":
            return 0
        if verb == "reset":
            system.reset(json.loads(read(sizes[0])))
            send("ready")
        elif verb == "step":
            state = json.loads(read(sizes[0]))
            pixels, mask, depth = read(sizes[1]), read(sizes[2]), read(sizes[3])
            image = None
            if state["frame"] is not None and len(pixels) > 0:
                f = state["frame"]
                image = np.frombuffer(pixels, dtype=np.uint8).reshape(f["height"], f["width"], 3).astype(np.float32)
            try:
                send("command", json.dumps(system.update(state, image)).encode())
            except Exception as e:  # the run ends as "system failed" with this text
                send("error", repr(e).encode())
        else:
            sys.stderr.write("dark_square_lander: unknown message %r\n" % verb)
            return 1


if __name__ == "__main__":
    sys.exit(main())
