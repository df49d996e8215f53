#!/usr/bin/env python3
"""quadseer-lander: a marker-landing system for touchdown's `exec:` protocol.

    landing_scenario campaign --system "exec:/usr/bin/python3 tests/outside/quadseer_lander.py"

Plain Python 3 with numpy. It speaks touchdown's system protocol, version 1
(header line `VERB N1 N2 ...`, then payloads of exactly those byte counts)
and asks for the camera image and the depth image.

Perception ("quadseer"):
  * grey image at half resolution, dark pixels by an adaptive (local-mean)
    threshold plus a global "black" level;
  * connected dark regions from run-length encoding and a vectorised
    union-find;
  * a quadrilateral per region from its extreme points (farthest-point fit);
  * a homography from the quad samples the marker grid at full resolution:
    black border, white quiet zone, then the code cells, which are compared
    with the target's code from an embedded copy of the dictionary (first 50
    ids of each) in all four rotations;
  * a rough confidence from border/quiet-zone contrast;
  * the accepted quad's centre is projected through the pinhole camera onto
    the ground (z = 0) for the target estimate.
  The depth image gives a coarse height map of what is below and ahead of
  the drone (obstacle floor while flying, a clear-column check while
  descending).

Flight (a small state machine):
  warmup   -> wait for the camera to deliver a usable first frame
  climb    -> climb vertically to the transit altitude (above tall trees)
  search   -> fly to the GPS target, then an expanding pattern around it,
              a second round lower for small markers
  confirm  -> centre over the marker at the confirmation altitude and
              require 3 s of continuous sightings
  descend  -> committed descent with visual re-centring; re-acquire (climb)
              if the marker is lost high up; hold if the column is blocked
  land     -> switch to the land mode close to the ground

Debugging: set LANDER_DEBUG=/path/file to log one line per camera frame.
"""
import json
import os
import sys
import warnings

import numpy as np

PROTOCOL = 1
NAME = "quadseer-lander"

# ---------------------------------------------------------------- tunables
TRANSIT_MIN_ALT = 12.5     # m, clears the tallest trees in the test world
TRANSIT_MAX_ALT = 16.0
SEARCH_RADIUS = 3.5        # m, first ring of the search pattern
CONFIRM_S = 3.0            # s of continuous sightings before committing
SIGHTING_GAP_S = 0.5       # a longer gap breaks "continuous"
LOCK_JUMP_M = 1.5          # a sighting further than this from the estimate re-locks
DESCENT_GATE_M = 1.0       # during descent only sightings this close count
BLIND_ALT = 2.0            # m, below this the marker may overfill the view
LAND_ALT = 0.45            # m, switch to the land mode
CLEARANCE_M = 2.0          # m above obstacles while flying around
COLUMN_MARGIN_M = 0.4      # m added to the drone radius for the descent column
GUARD_MIN_ALT = 2.5        # m, near range of the depth camera
EXPOSURE_OK = 60.0         # grey level (median, half resolution) of a usable frame
CLOSE_RANGE_PX = 110.0     # px edge: close-range tracking mode
MIN_CONTRAST = 0.12

warnings.filterwarnings("ignore")
stdin = sys.stdin.buffer
stdout = sys.stdout.buffer


# ---------------------------------------------------------------- protocol
def read_header():
    line = stdin.readline()
    if not line:
        sys.exit(0)
    words = line.decode("ascii").split()
    if not words:
        sys.exit(0)
    return words[0], [int(w) for w in words[1:]]


def read(n):
    chunks, got = [], 0
    while got < n:
        data = stdin.read(n - got)
        if not data:
            sys.exit(0)
        chunks.append(data)
        got += len(data)
    return b"".join(chunks)


def send(verb, payload=None):
    if payload is None:
        stdout.write((verb + "\n").encode("ascii"))
    else:
        stdout.write(("%s %d\n" % (verb, len(payload))).encode("ascii") + payload)
    stdout.flush()


# ---------------------------------------------------------------- dictionary
def dictionary_code(name, marker_id):
    """(cells per side, code bits as an n*n 0/1 array, 1 = white) or (n, None)."""
    key = name.upper()
    if key.startswith("DICT_"):
        key = key[5:]
    family = key if key in CODES else key.split("_")[0]
    if family not in CODES:
        return 6, None
    n, table = CODES[family]
    codes = table.split()
    if not 0 <= marker_id < len(codes):
        return n, None
    value = int(codes[marker_id], 16)
    bits = [(value >> (n * n - 1 - i)) & 1 for i in range(n * n)]
    return n, np.array(bits, dtype=np.uint8).reshape(n, n)


def code_table(name):
    key = name.upper()
    if key.startswith("DICT_"):
        key = key[5:]
    family = key if key in CODES else key.split("_")[0]
    if family not in CODES:
        return None
    n, table = CODES[family]
    out = []
    for c in table.split():
        v = int(c, 16)
        out.append(np.array([(v >> (n * n - 1 - i)) & 1 for i in range(n * n)],
                            dtype=np.uint8).reshape(n, n))
    return out


# ---------------------------------------------------------------- image tools
def box_mean(img, r):
    """Mean over a (2r+1)^2 window (clamped at the borders) via an integral image."""
    h, w = img.shape
    ii = np.zeros((h + 1, w + 1), dtype=np.float64)
    ii[1:, 1:] = img.cumsum(0).cumsum(1)
    y0 = np.clip(np.arange(h) - r, 0, h)
    y1 = np.clip(np.arange(h) + r + 1, 0, h)
    x0 = np.clip(np.arange(w) - r, 0, w)
    x1 = np.clip(np.arange(w) + r + 1, 0, w)
    s = ii[y1][:, x1] - ii[y0][:, x1] - ii[y1][:, x0] + ii[y0][:, x0]
    area = (y1 - y0)[:, None] * (x1 - x0)[None, :]
    return (s / area).astype(np.float32)


def components(mask):
    """Connected regions (8-connected) of a boolean mask as runs.

    Returns (row, start, end_inclusive, label) arrays, labels compact 0..k-1."""
    h, w = mask.shape
    wp = w + 2
    padded = np.zeros((h, wp), dtype=np.int8)
    padded[:, 1:-1] = mask
    d = np.diff(padded, axis=1)
    rows, starts = np.nonzero(d == 1)
    _, ends = np.nonzero(d == -1)
    ends = ends - 1
    n = rows.size
    if n == 0:
        return rows, starts, ends, np.zeros(0, dtype=np.int64)
    key_s = rows * wp + starts
    key_e = rows * wp + ends
    has_prev = rows > 0
    lo = np.searchsorted(key_e, (rows - 1) * wp + starts - 1, side="left")
    hi = np.searchsorted(key_s, (rows - 1) * wp + ends + 1, side="right")
    counts = np.where(has_prev, np.maximum(hi - lo, 0), 0)
    total = int(counts.sum())
    parent = np.arange(n)
    if total:
        src = np.repeat(np.arange(n), counts)
        first = np.repeat(np.cumsum(counts) - counts, counts)
        dst = np.repeat(lo, counts) + (np.arange(total) - first)
        for _ in range(200):
            ps, pd = parent[src], parent[dst]
            diff = ps != pd
            if not diff.any():
                break
            ps, pd = ps[diff], pd[diff]
            np.minimum.at(parent, np.maximum(ps, pd), np.minimum(ps, pd))
            while True:
                pp = parent[parent]
                if np.array_equal(pp, parent):
                    break
                parent = pp
    _, labels = np.unique(parent, return_inverse=True)
    return rows, starts, ends, labels


def fit_quad(points):
    """Four corners of a convex blob from its extreme points (farthest-point fit)."""
    c = points.mean(axis=0)
    p0 = points[np.argmax(((points - c) ** 2).sum(1))]
    p2 = points[np.argmax(((points - p0) ** 2).sum(1))]
    axis = p2 - p0
    length2 = float(axis @ axis)
    if length2 < 16.0:
        return None
    cross = (points[:, 0] - p0[0]) * axis[1] - (points[:, 1] - p0[1]) * axis[0]
    p1 = points[np.argmax(cross)]
    p3 = points[np.argmin(cross)]
    if cross.max() < 0.15 * length2 or -cross.min() < 0.15 * length2:
        return None
    quad = np.array([p0, p1, p2, p3], dtype=np.float64)
    # clockwise as seen in the image (x right, y down), like OpenCV's corners
    e0, e1 = quad[1] - quad[0], quad[2] - quad[1]
    if e0[0] * e1[1] - e0[1] * e1[0] < 0:
        quad = quad[[0, 3, 2, 1]]
    return quad


def homography(quad):
    """H mapping unit-square (s, t) -> image for corners (0,0),(1,0),(1,1),(0,1)."""
    src = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    a, b = [], []
    for (s, t), (u, v) in zip(src, quad):
        a.append([s, t, 1, 0, 0, 0, -u * s, -u * t]); b.append(u)
        a.append([0, 0, 0, s, t, 1, -v * s, -v * t]); b.append(v)
    try:
        h = np.linalg.solve(np.array(a), np.array(b))
    except np.linalg.LinAlgError:
        return None
    return np.append(h, 1.0).reshape(3, 3)


def sample(grey, H, st):
    """Grey values at unit-square coordinates st (k x 2), bilinear, NaN outside."""
    p = np.c_[st, np.ones(len(st))] @ H.T
    u, v = p[:, 0] / p[:, 2], p[:, 1] / p[:, 2]
    h, w = grey.shape
    ok = (u >= 0) & (v >= 0) & (u <= w - 1.001) & (v <= h - 1.001)
    out = np.full(len(st), np.nan, dtype=np.float64)
    if ok.any():
        uu, vv = u[ok], v[ok]
        x0, y0 = uu.astype(np.int64), vv.astype(np.int64)
        fx, fy = uu - x0, vv - y0
        out[ok] = (grey[y0, x0] * (1 - fx) * (1 - fy) + grey[y0, x0 + 1] * fx * (1 - fy)
                   + grey[y0 + 1, x0] * (1 - fx) * fy + grey[y0 + 1, x0 + 1] * fx * fy)
    return out


# ---------------------------------------------------------------- the system
class QuadseerLander:
    def reset(self, setup):
        cam = setup["camera"]
        self.width, self.height = int(cam["width"]), int(cam["height"])
        self.fx = float(cam["fx"])
        K = np.array([[self.fx, 0, self.width / 2.0], [0, self.fx, self.height / 2.0], [0, 0, 1.0]])
        self.K_inv = np.linalg.inv(K)
        self.T_body_camera = np.array(cam["T_body_camera"], dtype=float)
        self.gps = np.array(setup["gps_target"], dtype=float)
        self.marker_id = int(setup.get("marker_id", 0))
        self.marker_size = float(setup.get("marker_size", 1.0))
        self.radius = float(setup.get("drone_radius", 0.5))
        self.cells, self.code = dictionary_code(str(setup.get("dictionary", "4X4_50")), self.marker_id)
        self.table = code_table(str(setup.get("dictionary", "4X4_50")))
        # the code in its four rotations, for matching
        self.codes = [] if self.code is None else [np.rot90(self.code, k) for k in range(4)]
        # altitudes for this marker: its edge ~70 px while confirming, ~45 px while searching low
        self.confirm_alt = float(np.clip(self.marker_size * self.fx / 70.0, 4.0, 9.0))
        self.search_low_alt = float(np.clip(self.marker_size * self.fx / 45.0, 6.0, 11.0))
        # pixel grid for depth sub-sampling
        step = 8
        us, vs = np.meshgrid(np.arange(step // 2, self.width, step), np.arange(step // 2, self.height, step))
        self.depth_uv = (vs.ravel(), us.ravel())
        self.depth_rays = (self.K_inv @ np.vstack([us.ravel(), vs.ravel(), np.ones(us.size)])).T
        # flight state
        self.phase = "warmup"
        self.transit_alt = None
        self.estimate = None
        self.seen_since = None
        self.last_seen = -1e9
        self.waypoint = 0
        self.wp_arrived = None
        self.search_round = 0
        self.committed = False
        self.landing = False
        self.obstacles = np.zeros((0, 3))
        self.debug = os.environ.get("LANDER_DEBUG")
        if self.debug:
            with open(self.debug, "a") as f:
                f.write("reset %s\n" % json.dumps(setup))

    # ------------------------------------------------------------ perception
    def detect(self, image, T_world_camera):
        b, g, r = image[:, :, 0], image[:, :, 1], image[:, :, 2]
        grey = (b * 0.114 + g * 0.587 + r * 0.299).astype(np.float32)
        h2, w2 = grey.shape[0] // 2, grey.shape[1] // 2
        half = 0.25 * (grey[0:2 * h2:2, 0:2 * w2:2] + grey[1:2 * h2:2, 0:2 * w2:2]
                       + grey[0:2 * h2:2, 1:2 * w2:2] + grey[1:2 * h2:2, 1:2 * w2:2])
        stats = {"median": float(np.median(half[::4, ::4]))}
        bright = float(np.percentile(half[::2, ::2], 95))
        local = box_mean(half, max(6, w2 // 24))
        dark = (half < local - np.maximum(5.0, 0.12 * local)) | (half < 0.3 * bright)
        rows, starts, ends, labels = components(dark)
        found = []
        if labels.size == 0:
            return found, stats
        k = int(labels.max()) + 1
        lengths = (ends - starts + 1).astype(np.float64)
        area = np.bincount(labels, weights=lengths, minlength=k)
        x0 = np.full(k, 1 << 30); np.minimum.at(x0, labels, starts)
        x1 = np.full(k, -1); np.maximum.at(x1, labels, ends)
        y0 = np.full(k, 1 << 30); np.minimum.at(y0, labels, rows)
        y1 = np.full(k, -1); np.maximum.at(y1, labels, rows)
        bw, bh = x1 - x0 + 1, y1 - y0 + 1
        keep = ((area >= 20) & (bw >= 5) & (bh >= 5) & (bw < 0.9 * w2) & (bh < 0.9 * h2)
                & (x0 > 1) & (y0 > 1) & (x1 < w2 - 2) & (y1 < h2 - 2)
                & (area <= 1.05 * bw * bh) & (np.maximum(bw, bh) <= 3.0 * np.minimum(bw, bh)))
        ids = np.nonzero(keep)[0]
        if ids.size == 0:
            return found, stats
        ids = ids[np.argsort(-area[ids])][:14]
        order = np.argsort(labels, kind="stable")
        bounds = np.searchsorted(labels[order], np.arange(k + 1))
        for c in ids:
            sel = order[bounds[c]:bounds[c + 1]]
            pts = np.vstack([np.c_[starts[sel], rows[sel]], np.c_[ends[sel], rows[sel]]]).astype(np.float64)
            quad = fit_quad(pts)
            if quad is None:
                continue
            sides = np.linalg.norm(quad - np.roll(quad, -1, axis=0), axis=1)
            if sides.min() < 4.0 or sides.max() > 2.2 * sides.min():
                continue
            qa = 0.5 * abs(np.cross(quad[2] - quad[0], quad[3] - quad[1]))
            if qa <= 0 or area[c] > 1.25 * qa or area[c] < 0.2 * qa:
                continue
            # half-res pixel centres -> full-res, grown half a pixel outwards
            centre = quad.mean(axis=0)
            quad = centre + (quad - centre) * (1.0 + 1.0 / max(sides.mean(), 1.0))
            quad = quad * 2.0 + 0.5
            cand = self.verify(grey, quad)
            if cand is None:
                continue
            ground = self.to_ground(T_world_camera, cand["centre"])
            if ground is None:
                continue
            cand["ground"] = ground
            found.append(cand)
        return found, stats

    def verify(self, grey, quad):
        """Sample the marker grid through the quad; None unless it looks like a marker."""
        H = homography(quad)
        if H is None:
            return None
        n = self.cells
        m = n + 2                              # cells across the black border
        offs = (np.array([0.3, 0.5, 0.7]) - 0.5)
        sub = np.array([(a, b) for a in offs for b in offs])
        def cells_mean(ij):
            centres = (np.asarray(ij, dtype=np.float64) + 0.5) / m
            st = (centres[:, None, :] + sub[None, :, :] / m).reshape(-1, 2)
            vals = sample(grey, H, st).reshape(len(ij), len(sub))
            return np.nanmean(vals, axis=1) if np.isfinite(vals).any() else np.full(len(ij), np.nan)
        border = [(i, j) for i in range(m) for j in range(m) if i in (0, m - 1) or j in (0, m - 1)]
        quiet = [(i, j) for i in range(-1, m + 1) for j in range(-1, m + 1)
                 if i in (-1, m) or j in (-1, m)]
        inner = [(i, j) for j in range(1, m - 1) for i in range(1, m - 1)]   # row-major (row j)
        with np.errstate(all="ignore"):
            vb = cells_mean(border)
            vq = cells_mean(quiet)
        if np.isnan(vb).any() or np.isnan(vq).mean() > 0.3:
            return None
        vq = vq[np.isfinite(vq)]
        black, white = float(np.median(vb)), float(np.median(vq))
        contrast = (white - black) / (white + 1.0)
        if contrast < MIN_CONTRAST:
            return None
        thr = 0.5 * (black + white)
        border_ok = float((vb < thr).mean())
        quiet_ok = float((vq > thr).mean())
        if border_ok < 0.85 or quiet_ok < 0.7:
            return None
        edge = float(np.linalg.norm(quad - np.roll(quad, -1, axis=0), axis=1).mean())
        confidence = float(np.clip(contrast * 1.6, 0, 1) * border_ok * quiet_ok)
        centre = self.diagonal_centre(quad)
        result = {"corners": quad, "edge": edge, "centre": centre, "confidence": confidence,
                  "id": -1, "match": False}
        if edge >= CLOSE_RANGE_PX:
            # close-range tracking: cells are large and the border/quiet-zone check is
            # already decisive at this size, so the code read is skipped
            result["match"] = True
            result["id"] = self.marker_id
            return result
        with np.errstate(all="ignore"):
            vi = cells_mean(inner)
        if np.isnan(vi).any():
            return result
        bits = (vi > thr).astype(np.uint8).reshape(n, n)
        # a cell too close to the threshold makes the read unreliable
        margin = np.abs(vi - thr) / max(white - black, 1.0)
        if margin.min() < 0.08:
            confidence *= 0.5
        result["confidence"] = confidence
        for code in self.codes:
            if np.array_equal(bits, code):
                result["match"] = True
                result["id"] = self.marker_id
                return result
        if self.table is not None:
            for i, code in enumerate(self.table):
                if any(np.array_equal(bits, np.rot90(code, r)) for r in range(4)):
                    result["id"] = i
                    break
        return result

    @staticmethod
    def diagonal_centre(q):
        p, r = q[0], q[2] - q[0]
        s, d = q[1], q[3] - q[1]
        den = r[0] * d[1] - r[1] * d[0]
        if abs(den) < 1e-9:
            return q.mean(axis=0)
        t = ((s[0] - p[0]) * d[1] - (s[1] - p[1]) * d[0]) / den
        return p + t * r

    def to_ground(self, T_world_camera, uv):
        ray = T_world_camera[:3, :3] @ (self.K_inv @ np.array([uv[0], uv[1], 1.0]))
        origin = T_world_camera[:3, 3]
        if ray[2] >= -1e-6:
            return None
        return (origin - origin[2] / ray[2] * ray)[:2]

    def update_obstacles(self, depth, T_world_camera):
        d = depth[self.depth_uv]
        ok = np.isfinite(d) & (d > 0.05)
        pts_cam = self.depth_rays[ok] * d[ok][:, None]
        pts = pts_cam @ T_world_camera[:3, :3].T + T_world_camera[:3, 3]
        self.obstacles = pts[pts[:, 2] > 0.3]

    def obstacle_top(self, xy, radius):
        if self.obstacles.shape[0] == 0:
            return 0.0
        dist2 = ((self.obstacles[:, :2] - xy) ** 2).sum(1)
        near = dist2 < radius * radius
        return float(self.obstacles[near, 2].max()) if near.any() else 0.0

    # ------------------------------------------------------------ control
    def pick(self, found):
        accepted = [c for c in found if c["match"]]
        if not accepted:
            return None
        if self.committed and self.estimate is not None:
            near = [c for c in accepted if np.linalg.norm(c["ground"] - self.estimate) < DESCENT_GATE_M]
            if not near:
                return None
            return min(near, key=lambda c: np.linalg.norm(c["ground"] - self.estimate))
        # the biggest view of the marker is the most reliable one
        return max(accepted, key=lambda c: c["edge"])

    def update(self, state, image, depth):
        t = float(state["t"])
        pos = np.array(state["position"], dtype=float)
        xy, z = pos[:2], pos[2]
        answer = {}
        chosen = None
        if self.transit_alt is None:
            self.transit_alt = float(np.clip(max(z, TRANSIT_MIN_ALT), TRANSIT_MIN_ALT, TRANSIT_MAX_ALT))

        if image is not None:
            T_wc = np.array(state["T_world_body"], dtype=float) @ self.T_body_camera
            found, stats = self.detect(image, T_wc)
            if depth is not None:
                self.update_obstacles(depth, T_wc)
            if self.phase == "warmup" and stats["median"] >= EXPOSURE_OK:
                self.phase = "climb"
            if self.phase != "warmup":
                chosen = self.pick(found)
            dets = []
            for c in found:
                g = c["ground"]
                dets.append({"corners": [[float(u), float(v)] for u, v in c["corners"]],
                             "id": int(c["id"]), "quality": round(c["edge"], 2),
                             "confidence": round(c["confidence"], 3),
                             "accepted": bool(c is chosen),
                             "ground": [float(g[0]), float(g[1])]})
            answer["detections"] = dets
            if chosen is not None:
                g = chosen["ground"]
                if self.estimate is None or np.linalg.norm(g - self.estimate) > LOCK_JUMP_M:
                    self.estimate = g.copy()
                    self.seen_since = t
                else:
                    self.estimate = 0.6 * self.estimate + 0.4 * g
                    if self.seen_since is None:
                        self.seen_since = t
                self.last_seen = t
            if self.debug:
                with open(self.debug, "a") as f:
                    f.write("t=%.1f z=%.2f phase=%s median=%.1f found=%d %s est=%s\n" % (
                        t, z, self.phase, stats["median"], len(found),
                        [(round(c["edge"]), c["id"], c["match"], round(c["confidence"], 2)) for c in found],
                        None if self.estimate is None else np.round(self.estimate, 2).tolist()))
        if t - self.last_seen > SIGHTING_GAP_S:
            self.seen_since = None

        vxy, vz = np.zeros(2), 0.0
        if self.phase == "warmup":
            answer["phase"] = "warmup"
        elif self.committed:
            vxy, vz = self.descend(answer, t, xy, z, state)
        else:
            vxy, vz = self.approach(answer, t, xy, z)
        answer["velocity"] = [float(vxy[0]), float(vxy[1]), float(vz)]
        if self.landing:
            answer["land"] = True
        return answer

    def approach(self, answer, t, xy, z):
        lost = t - self.last_seen
        if self.estimate is not None and lost > 4.0:
            self.estimate = None               # lost it: back to searching
        if self.phase == "climb" and z >= self.transit_alt - 0.7:
            self.phase = "search"
        if self.phase == "climb" and self.estimate is None:
            goal_xy, goal_z, vmax = xy.copy(), self.transit_alt, 0.0
        elif self.estimate is None:
            self.phase = "search"
            goal_xy, goal_z = self.search_goal(t, xy)
            vmax = 3.0
        else:
            self.phase = "confirm"
            goal_xy = self.estimate
            off = float(np.linalg.norm(goal_xy - xy))
            goal_z = self.confirm_alt if off < 2.0 else max(self.confirm_alt, min(z, self.transit_alt))
            vmax = 1.5 if off < 3.0 else 3.0
            centred = off < 0.35 and abs(z - self.confirm_alt) < 0.3
            if self.seen_since is not None and t - self.seen_since >= CONFIRM_S and centred:
                self.committed = True
                self.phase = "descend"
                answer["descent_started"] = True
                answer["target"] = [float(self.estimate[0]), float(self.estimate[1])]
        # keep clear of whatever the depth camera sees below and ahead
        vxy = np.clip(1.0 * (goal_xy - xy), -vmax, vmax)
        speed = float(np.linalg.norm(vxy))
        if speed > vmax and speed > 0:
            vxy *= vmax / speed
        ahead = xy + 1.5 * vxy
        floor = max(self.obstacle_top(xy, self.radius + 1.0),
                    self.obstacle_top(ahead, self.radius + 1.0))
        if floor > 0:
            goal_z = max(goal_z, floor + CLEARANCE_M)
            if z < floor + CLEARANCE_M - 0.3:
                vxy = np.zeros(2)
        vz = float(np.clip(0.9 * (goal_z - z), -1.2, 1.5))
        answer["phase"] = self.phase
        return vxy, vz

    def search_goal(self, t, xy):
        pattern = [(0, 0), (1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)]
        ring = 1.0 if self.search_round % 2 == 0 else 1.4
        off = np.array(pattern[self.waypoint % len(pattern)], dtype=float) * SEARCH_RADIUS * ring
        goal = self.gps + off
        alt = self.transit_alt if self.search_round == 0 else self.search_low_alt
        if np.linalg.norm(goal - xy) < 0.8:
            if self.wp_arrived is None:
                self.wp_arrived = t
            elif t - self.wp_arrived > 1.0:
                self.wp_arrived = None
                self.waypoint += 1
                if self.waypoint % len(pattern) == 0:
                    self.search_round += 1
        return goal, alt

    def descend(self, answer, t, xy, z, state):
        err = self.estimate - xy
        off = float(np.linalg.norm(err))
        lost = t - self.last_seen
        vxy = np.clip(1.0 * err, -0.8, 0.8)
        rate = min(1.2, 0.25 + 0.2 * z)
        if z < LAND_ALT or state.get("on_ground"):
            self.landing = True
        if self.landing:
            answer["phase"] = "land"
            return vxy, -0.5
        if z > BLIND_ALT and lost > 1.5:
            # lost it high up: climb a little and look again
            answer["phase"] = "reacquire"
            return vxy * 0.5, (0.8 if z < self.confirm_alt + 1.0 else 0.0)
        if z > GUARD_MIN_ALT:
            top = self.obstacle_top(xy, self.radius + COLUMN_MARGIN_M)
            if top > 0 and z - top < 1.5:
                answer["phase"] = "hold"
                return vxy, (0.3 if z - top < 1.0 else 0.0)
        answer["phase"] = "descend"
        if off > 0.5 and z > BLIND_ALT:
            return vxy, 0.0
        return vxy, -rate


def main():
    verb, sizes = read_header()
    if verb != "touchdown-system" or sizes != [PROTOCOL]:
        sys.stderr.write("%s: the host speaks %s %s, not protocol 1\n" % (NAME, verb, sizes))
        return 1
    hello = json.dumps({"name": NAME, "wants": ["image", "depth"]}).encode()
    stdout.write(b"touchdown-system %d %d\n" % (PROTOCOL, len(hello)) + hello)
    stdout.flush()
    system = QuadseerLander()
    while True:
        verb, sizes = read_header()
        if verb == "bye":
            return 0
        if verb == "reset":
            system.reset(json.loads(read(sizes[0])))
            send("ready")
        elif verb == "step":
            state = json.loads(read(sizes[0]))
            payloads = [read(s) for s in sizes[1:]]
            while len(payloads) < 3:
                payloads.append(b"")
            pixels, _mask, depth_bytes = payloads[0], payloads[1], payloads[2]
            image = depth = None
            frame = state.get("frame")
            if frame is not None and len(pixels) > 0:
                w, h = int(frame["width"]), int(frame["height"])
                image = np.frombuffer(pixels, dtype=np.uint8).reshape(h, w, 3).astype(np.float32)
                if len(depth_bytes) == 4 * w * h:
                    depth = np.frombuffer(depth_bytes, dtype="<f4").reshape(h, w)
            try:
                send("command", json.dumps(system.update(state, image, depth)).encode())
            except Exception as e:  # the run ends as "system failed" with this text
                send("error", repr(e).encode())
        else:
            sys.stderr.write("%s: unknown message %r\n" % (NAME, verb))
            return 1


# ArUco / AprilTag codes (first 50 ids of each family; the _50 ... _1000 sets
# of a family share them): cells per side, then one hex word per id, bits row
# by row from the top-left cell, 1 = white.
CODES = {
    '4X4': (4, """
        b532 f9a 332d 9946 549e 79cd 9e2e c4f2 feda cf56 f991 11a7 eb7 2a0f
        24b1 263e 4665 6600 6c5e 76af 868b b02b ccd5 dd82 fe47 9471 ace4 a554
        2123 346f 4415 57b2 9ecf f0cb 8ae 929 1875 4ff df6 1c5a 1718 2a28
        328c 38b2 24e8 2eeb 2d3f 4b64 502e 5013"""),
    '5X5': (5, """
        145b2bc 1c06e6 1af0edd 10395f7 1aeb524 1d4082d d3d7ec e2146b 10d6132
        1313fa5 13cee03 1a2dac0 1e62b11 5e7166 1fcfca8 51e37f 97a758 bea26f
        f64dc4 1061de8 12dda75 150e440 16b0ca1 ba12de 19cd023 1a59972 1c3ce8b
        224246 3b9672 24223b 27376e 368873 40d0ce 4aaac8 4643ba 7a6fea 998aac
        82d101 9aad1d 863c72 ad2825 a52f9e d849f7 c309d9 da7e31 e9627a e9b997
        f94806 f59125 f6b7d7"""),
    '6X6': (6, """
        1e3dd82a6 efba3891 15907eacd c91b3069e d607d6e15 d8e8e0e68 4268b41f5
        88a50f29a 307d524fd 3c2f34b3c 45dfc74e3 48d85b257 710558fc6 86dcfad07
        8d72a93f6 a2b89dcde 9fd1e9c4 154dbd18f 300a310e2 4807efafd 56df11db6
        66883274c 76e8cb781 9a53d9cf3 a9cb84024 c67549490 c1d288941 e7480852b
        ea2fca848 e963b77b1 fa36652af 65bff7bd 541d72d6 cf7246a2 1338a39eb
        15a893e74 3a417ee9e 4f11e26c0 530db6d20 589bfae34 6409e8a0b 60537a891
        6159069ba 6bff78d7b 70ad96a4f 75846f71a 7a95192fc 8609760aa 8a2d44c3f
        93eb78b14"""),
    '7X7': (7, """
        1bab8d94b9415 1c837e27c8156 13d545758ba4f 14cce0b6fd298 18d78f62664ac
        b1002846b3dc 1a6d77cdea890 7942db1117b6 1120e3ead2d3c 176cb631adc7e
        1ea01a305e921 44ce170a834 a9e6d72e91e1 13c49108c4733 17bfe64d79397
        19c220b60b52f 1a7e0c2e43f16 3c33d9d91db 4d979854e0f1 70fa9aec8226
        752095d3c3d3 8da908f679ba 91254fbd3c57 bced87c93150 e945bdf45f11
        128bbc45026b2 136252ac9db47 143a9285b05f0 176f1cc62d9a1 1976bbb97b630
        1a7cbdd6f0666 1e528467fa339 1fbada33e77cd 748c49dd09dd c430fc48761e
        159a86df3b86 1c81a9871c04 293fb340c448 3345c234cbda 56a104fc3668
        52d271253f46 59eea9b7e8ad 6bd27f3c6cf8 7ee957b07be7 89a053e9fe80
        9081c90855ea be3226d06804 bd64e4807abb df36483e2b84 e555f24151c7"""),
    'ARUCO_ORIGINAL': (5, """
        1084210 1084217 1084209 108420e 10842f0 10842f7 10842e9 10842ee
        1084130 1084137 1084129 108412e 10841d0 10841d7 10841c9 10841ce
        1085e10 1085e17 1085e09 1085e0e 1085ef0 1085ef7 1085ee9 1085eee
        1085d30 1085d37 1085d29 1085d2e 1085dd0 1085dd7 1085dc9 1085dce
        1082610 1082617 1082609 108260e 10826f0 10826f7 10826e9 10826ee
        1082530 1082537 1082529 108252e 10825d0 10825d7 10825c9 10825ce
        1083a10 1083a17"""),
    'APRILTAG_16H5': (4, """
        d8c4 a574 562c 9da2 659e d6fe 1acd a2e7 9a7f b6a8 d01c d50f 21b0 6ce2
        4e31 8f5 3c90 2dc9 c0a5 f162 ec87 a9ea 42fb b838 3b97 b5ce fab5 cab
        53e0 74f5"""),
    'APRILTAG_25H9': (5, """
        11fa755 db164f 2da1bd 16726af e650e9 1ba2558 cfd5dc 1ab74c1 1ce8abb
        22caf6 1c93702 1049b14 ea27b6 130e14f 973035 82836d 1580f8d 103b372
        46ef9d 120b8ea 1147df4 7fd90b 8d5276 144e803 685587 4be1c2 121c512
        1e42cd 14a9e26 1baf982 1fd1d34 141679 116a0be 1b8ddb e7133a"""),
    'APRILTAG_36H10': (6, """
        e16549538 323584a04 6bedfc5e4 d9bd732d4 5773de26c f52b50f9c 2e5b999bc
        7fa7ed722 48bfcf1ca eb40c1cea d798fdba6 5cd436b0e 724215efe c812ec4c1
        1bb263361 b9caaae51 372640ea9 8d5689899 dc6ef5605 51e13a6d5 28c95ed4d
        9b199066d c625e4dbd eeddc6a33 a87bbd247 26f7562b7 775f1192f e3e82a760
        db74091a8 a65c75b38 f7a233424 2dd2dabe4 9e8a57ed4 c0ba10b4c 1346e9e6c
        b1166445c 4a76ad3bc 85fe46312 ad69796ea 2015d2646 93b55b066 ca9d1fab6
        bb2368d2e 346bc35fe a0cf71f89 531fb85a9 f17f35299 9850d3905 7bf05a225
        c5a8977e5"""),
    'APRILTAG_36H11': (6, """
        21a146bab 92d18fe9b 7089014bb 193979e27 44153d3d7 35cd5b8cf a10ba56a0
        2b874a608 b57fb8d44 4e20b5a64 61d897f2c ab3469ffc 594ca45c2 fa1c2d2e2
        97c24b972 75928624a 1caafe99a 3236ddc16 884e527d6 5771a8c7e f52925b81
        2e59cc1a1 7fa58ab31 eb43384f9 3913d5345 d79b1a3b5 dfbe768d 5cd7a031d
        b9c8f7a4b 46987e06b 6e0c5d527 5bc567bb4 1e6302bc2 8ac7d046a a65fe2326
        5400eb616 f7a066836 2dd0afdf6 3b9cb60b1 ad6a1caf9 93b62efb5 bb210d93d
        dee55094b a0cd1479b 2a23abb27 4f67f4b5f 58a815818 743427d64 1dec40874
        892ab3a02"""),
}


if __name__ == "__main__":
    sys.exit(main())
