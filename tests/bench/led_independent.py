#!/usr/bin/python3
"""led_pose on LED sequences from an independent renderer (render_led_sequence.py, written outside touchdown).

Renders one sequence per (constellation, seed) with the independent renderer, runs `led_pose SEQ --jsonl
--constellation OUR_FILE` on it in each mode, compares every frame with the renderer's ground_truth.jsonl and prints
per mode and per distance band (|t_true|: 0.4-1, 1-2, 2-3 m; the far end of the sweep reaches ~3.2 m and counts in
2-3) a markdown table:

  success        ok, position error <= 0.1 m and rotation error <= 0.1 rad (fraction of all frames)
  wrong-ok       ok but more than 0.1 m or 0.1 rad wrong
  dangerous      wrong-ok and beyond 3 sigma (position error > 3 sigma_pos or rotation error > 3 sigma_rot):
                 a wrong pose its own sigma does not warn about; each one is listed
  paper success  the source paper's rule: ok and reprojection <= 10 px ("reproj_px")
  NEES           when led_pose prints "covariance" (6x6, twist xi = (rho, phi), T_true = exp(xi^) T_est):
                 mean of xi' Cov^-1 xi over ok frames (6 for an honest covariance) and the fraction beyond the
                 99.9 % chi-square(6) bound 22.458
  ms             median "ms" per frame (machine- and load-dependent)

Sequences are cached in --work: a sequence is rendered once per (constellation LEDs as the renderer reads them,
seed, frames, flags, renderer source) and reused while complete. About 1 MB of disk per frame.

Modes: single (led_pose's per-frame poses), fuse (--fuse), attitude (--attitude SEQ/attitude.jsonl, the
renderer's IMU "down" directions; needs a led_pose that has the option); combine with '+', e.g. fuse+attitude.

Exit status: 0 done, 1 a --require-* floor or ceiling missed (or a mode without frames to check), 2 bad
arguments or a missing tool (77 instead with --skip-missing when the renderer, numpy or cv2 is missing),
3 a tool failed.

Example (docs/benchmarks.md):
  tests/bench/led_independent.py --work /tmp/led_independent --seeds 101-104 --mix --frames 600 \\
      --modes single,fuse --json /tmp/led_independent.json
"""
import argparse
import collections
import concurrent.futures
import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
import threading
import time

PROG = "led_independent.py"


def die(message, code=2):
    print("%s: %s" % (PROG, message), file=sys.stderr)
    sys.exit(code)


SKIP_CODE = 77  # --skip-missing: the renderer or its Python modules are missing (ctest's SKIP_RETURN_CODE)


def missing_tool(message, a):
    """A missing renderer or module: exit 2, or with --skip-missing say so and exit SKIP_CODE."""
    if a.skip_missing:
        print("%s: skipped: %s" % (PROG, message))
        sys.exit(SKIP_CODE)
    die(message)


try:
    import numpy as np
except ImportError:
    if "--skip-missing" in sys.argv:
        print("%s: skipped: %s lacks numpy (apt-get install python3-numpy)" % (PROG, sys.executable))
        sys.exit(77)
    die("%s lacks numpy: run this script with /usr/bin/python3 (apt-get install python3-numpy)" % sys.executable)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_RENDERER = os.environ.get("TOUCHDOWN_LED_RENDERER", "/work/shared/tools/render_led_sequence.py")
SUCCESS_POS_M, SUCCESS_ROT_RAD = 0.1, 0.1
PAPER_REPROJ_PX = 10.0
CHI2_6_999 = 22.458  # 99.9 % quantile of chi-square with 6 degrees of freedom
CHI2_3_999 = 16.266  # same, 3 degrees of freedom (the rho and phi blocks alone)
BANDS = [("0.4-1", 0.0, 1.0), ("1-2", 1.0, 2.0), ("2-3", 2.0, math.inf)]
FLAGS = ("fast", "distractors", "dropouts")
MIX = [(), ("fast",), ("distractors",), ("dropouts",)]  # --mix: seed k of the list gets MIX[k % 4]
MODE_FLAGS = {"fuse", "attitude"}
# The renderer's own reading of a constellation file (render_led_sequence.read_constellation).
RENDERER_LED_LINE = re.compile(r"xyz:\s*\[([^\]]+)\].*color:\s*([a-z]+)")
# One thread per process is what --jobs promises: keep numpy/OpenCV inside each process single-threaded.
CHILD_ENV = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OPENCV_FOR_THREADS_NUM="1")


CHILDREN, CHILDREN_LOCK, STOPPING = set(), threading.Lock(), threading.Event()


def run(cmd):
    """subprocess.run that stop_children() can end (a failed sequence stops the others)."""
    if STOPPING.is_set():
        raise ToolFailure("stopped")
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=CHILD_ENV)
    with CHILDREN_LOCK:
        CHILDREN.add(p)
    try:
        out, err = p.communicate()
    finally:
        with CHILDREN_LOCK:
            CHILDREN.discard(p)
    return subprocess.CompletedProcess(cmd, p.returncode, out, err)


def stop_children():
    STOPPING.set()
    with CHILDREN_LOCK:
        for p in CHILDREN:
            p.terminate()


# ---------------------------------------------------------------- arguments


def parse_seeds(text):
    seeds = []
    for part in text.split(","):
        part = part.strip()
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", part)
        if not m:
            raise ValueError("'%s' is not a seed or a range like 101-106" % part)
        lo, hi = int(m.group(1)), int(m.group(2) or m.group(1))
        if hi < lo:
            raise ValueError("range '%s' runs backwards" % part)
        seeds.extend(range(lo, hi + 1))
    if len(set(seeds)) != len(seeds):
        raise ValueError("a seed is given twice")
    return seeds


def parse_modes(text):
    modes = []
    for mode in (m.strip() for m in text.split(",")):
        parts = mode.split("+")
        if mode != "single" and not (parts and all(p in MODE_FLAGS for p in parts) and len(set(parts)) == len(parts)):
            raise ValueError("'%s' is not single, fuse, attitude or a '+' combination of fuse and attitude" % mode)
        if mode in modes:
            raise ValueError("mode '%s' is given twice" % mode)
        modes.append(mode)
    return modes


def arguments():
    ap = argparse.ArgumentParser(
        prog=PROG, description=__doc__.split("\n\n")[0], epilog="\n\n".join(__doc__.split("\n\n")[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--work", required=True, metavar="DIR",
                    help="render cache and led_pose outputs (created; sequences in it are reused)")
    ap.add_argument("--led-pose", default=os.path.join(REPO, "build", "apps", "led_pose"), metavar="PATH",
                    help="the led_pose binary (default: %(default)s)")
    ap.add_argument("--constellations", nargs="+", metavar="FILE",
                    help="touchdown constellation YAML files, one LED per line (default: every "
                         "tests/data/led_independent/*.yaml)")
    ap.add_argument("--seeds", default="101-104", help="seeds: a list and/or ranges, e.g. 101-106 or 1,2,3 "
                                                     "(default: %(default)s)")
    ap.add_argument("--frames", type=int, default=600, help="frames per sequence (default: %(default)s)")
    ap.add_argument("--fast", action="store_true", help="renderer --fast: three times faster motion")
    ap.add_argument("--distractors", action="store_true", help="renderer --distractors: white lamps in the image")
    ap.add_argument("--dropouts", action="store_true", help="renderer --dropouts: one LED missing in 3 of 25 frames")
    ap.add_argument("--mix", action="store_true",
                    help="alternate the renderer flags over the seeds: the k-th seed adds nothing, --fast, "
                         "--distractors, --dropouts for k mod 4 = 0..3 (on top of flags given explicitly)")
    ap.add_argument("--modes", default="single,fuse",
                    help="comma-separated led_pose modes: single, fuse, attitude or e.g. fuse+attitude "
                         "(default: %(default)s)")
    ap.add_argument("--attitude", action="store_true", help="add the mode 'attitude' to --modes")
    ap.add_argument("--no-depth", action="store_true", help="pass --no-depth to led_pose in every mode")
    ap.add_argument("--jobs", type=int, default=2,
                    help="sequences rendered and measured in parallel, one process each (default: %(default)s)")
    ap.add_argument("--json", metavar="FILE", help="write the summary (every figure and every dangerous frame) here")
    ap.add_argument("--list", type=int, default=100, metavar="N",
                    help="list at most N dangerous frames in the printed report (all are in --json; "
                         "default: %(default)s)")
    ap.add_argument("--discard-frames", action="store_true",
                    help="delete each rendered sequence once measured (saves disk; the next run renders again)")
    ap.add_argument("--renderer", default=DEFAULT_RENDERER,
                    help="the independent renderer (default: $TOUCHDOWN_LED_RENDERER or %s)" %
                         "/work/shared/tools/render_led_sequence.py")
    ap.add_argument("--python", default="/usr/bin/python3",
                    help="interpreter with numpy and cv2 for the renderer (default: %(default)s)")
    ap.add_argument("--skip-missing", action="store_true",
                    help="a missing renderer, numpy or cv2 is not an error: print why and exit %d (for ctest)" %
                         SKIP_CODE)
    ap.add_argument("--require-dangerous", type=int, metavar="N",
                    help="exit 1 when a mode has more than N dangerous frames")
    ap.add_argument("--require-success", type=float, metavar="F",
                    help="exit 1 when a mode's success fraction over all frames is below F")
    ap.add_argument("--require-success-2m", type=float, metavar="F",
                    help="exit 1 when a mode's success fraction over the frames within 2 m is below F")
    a = ap.parse_args()
    try:
        a.seed_list = parse_seeds(a.seeds)
        a.mode_list = parse_modes(a.modes)
    except ValueError as e:
        die(str(e))
    if a.attitude and "attitude" not in a.mode_list:
        a.mode_list.append("attitude")
    if a.frames < 2:
        die("--frames must be at least 2, got %d" % a.frames)
    if a.jobs < 1:
        die("--jobs must be at least 1, got %d" % a.jobs)
    if a.list < 0:
        die("--list must be 0 or more, got %d" % a.list)
    if a.require_dangerous is not None and a.require_dangerous < 0:
        die("--require-dangerous must be 0 or more, got %d" % a.require_dangerous)
    for name in ("require_success", "require_success_2m"):
        value = getattr(a, name)
        if value is not None and not 0 <= value <= 1:
            die("--%s must be a fraction in [0, 1], got %g" % (name.replace("_", "-"), value))
    if not a.constellations:
        folder = os.path.join(REPO, "tests", "data", "led_independent")
        a.constellations = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".yaml")) \
            if os.path.isdir(folder) else []
        if not a.constellations:
            die("no constellation files in %s: pass --constellations" % folder)
    stems = [os.path.splitext(os.path.basename(c))[0] for c in a.constellations]
    if len(set(stems)) != len(stems):
        die("two constellation files have the same name: %s" % ", ".join(sorted(stems)))
    return a


# ---------------------------------------------------------------- tools


def check_led_pose(path, modes):
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        die("led_pose not found at %s: build it (cmake --build build -j2 --target led_pose) or pass --led-pose" %
            path)
    try:
        out = subprocess.run([path, "--help"], capture_output=True, text=True, timeout=60)
        version = subprocess.run([path, "--version"], capture_output=True, text=True, timeout=60).stdout.strip()
    except (OSError, subprocess.TimeoutExpired) as e:
        die("cannot run %s: %s" % (path, e))
    if out.returncode != 0:
        die("%s --help failed (exit %d)" % (path, out.returncode))
    if any("attitude" in m.split("+") for m in modes) and "--attitude" not in out.stdout:
        die("%s has no --attitude option: drop 'attitude' from --modes" % path)
    return version


def check_renderer(a):
    if getattr(a, "renderer_checked", False):
        return
    a.renderer_checked = True
    if not os.path.isfile(a.renderer):
        missing_tool("the renderer %s does not exist: pass --renderer" % a.renderer, a)
    try:
        r = subprocess.run([a.python, "-c", "import numpy, cv2"], capture_output=True, text=True, timeout=120)
    except OSError as e:
        missing_tool("cannot run %s: %s" % (a.python, e), a)
    if r.returncode != 0:
        missing = "cv2: apt-get install python3-opencv" if "cv2" in r.stderr else \
            "numpy: apt-get install python3-numpy" if "numpy" in r.stderr else "numpy or cv2"
        missing_tool("%s lacks %s" % (a.python, missing), a)


def file_sha(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def read_constellation(path):
    """The LEDs as the renderer reads them, after checking that it reads every LED of the file."""
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except OSError as e:
        die("cannot read constellation %s: %s" % (path, e.strerror))
    leds, entries = [], 0
    for number, line in enumerate(lines, 1):
        code = line.split("#", 1)[0]
        entries += code.count("xyz:")
        m = RENDERER_LED_LINE.search(code)
        if m:
            try:
                xyz = [float(v) for v in m.group(1).split(",")]
            except ValueError:
                die("%s:%d: xyz: not three numbers" % (path, number))
            leds.append((xyz, m.group(2)))
    if entries != len(leds) or len(leds) < 4:
        die("%s: the renderer reads %d LEDs of %d: write each LED on one line as "
            "'- {xyz: [x, y, z], color: red, ...}' (xyz before color), at least 4" % (path, len(leds), entries))
    return leds


# ---------------------------------------------------------------- rendering


class Sequence:
    def __init__(self, a, constellation, leds, seed, flags):
        self.constellation = constellation
        self.name = os.path.splitext(os.path.basename(constellation))[0]
        self.seed, self.flags, self.frames = seed, tuple(flags), a.frames
        self.variant = "+".join(flags) or "plain"
        led_text = json.dumps(leds)
        folder = "%s-%s" % (self.name, hashlib.sha256(led_text.encode()).hexdigest()[:8])
        self.label = "%s/seed%d-%s" % (self.name, seed, self.variant)
        self.dir = os.path.join(a.work, "sequences", folder, "seed%d-n%d-%s" % (seed, a.frames, self.variant))
        self.out_dir = os.path.join(a.work, "led_pose", folder, "seed%d-n%d-%s" % (seed, a.frames, self.variant))
        # through JSON, so that it compares equal to the render.json it is written to (tuples become lists)
        self.key = json.loads(json.dumps({"renderer_sha256": a.renderer_sha, "leds": leds, "seed": seed,
                                          "frames": a.frames, "flags": list(flags)}))

    def complete(self):
        try:
            with open(os.path.join(self.dir, "render.json")) as f:
                if json.load(f) != self.key:
                    return False
            with open(os.path.join(self.dir, "ground_truth.jsonl")) as f:
                n = sum(1 for line in f if line.strip())
            last = "%06d" % (self.frames - 1)
            return n == self.frames and all(os.path.isfile(os.path.join(self.dir, last + ext))
                                            for ext in (".png", ".depth.png")) and \
                os.path.isfile(os.path.join(self.dir, "attitude.jsonl"))
        except (OSError, ValueError):
            return False

    def render(self, a):
        """Renders into DIR.part and renames it: an interrupted render never looks complete."""
        part = self.dir + ".part"
        shutil.rmtree(part, ignore_errors=True)
        os.makedirs(os.path.dirname(self.dir), exist_ok=True)
        cmd = [a.python, a.renderer, part, "--constellation", os.path.abspath(self.constellation),
               "--frames", str(self.frames), "--seed", str(self.seed)] + ["--" + f for f in self.flags]
        r = run(cmd)
        if r.returncode != 0:
            raise ToolFailure("the renderer failed on %s (exit %d): %s" % (self.label, r.returncode, last_line(r)))
        with open(os.path.join(part, "render.json"), "w") as f:
            json.dump(self.key, f)
        if os.path.isdir(self.dir):
            shutil.rmtree(self.dir)  # a stale render (other renderer source); render.json marks it as ours
        os.rename(part, self.dir)


class ToolFailure(Exception):
    def __init__(self, message, code=3):
        super().__init__(message)
        self.code = code


def last_line(result):
    lines = [s for s in (result.stderr or "").strip().splitlines() if s.strip()]
    return lines[-1] if lines else "(no message)"


# ---------------------------------------------------------------- geometry


def qmat(q):
    w, x, y, z = np.asarray(q, float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def rotvec(R):
    """log of a rotation matrix, robust near 0 and pi (through the quaternion)."""
    w = math.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    v = np.array([math.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2,
                  math.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2,
                  math.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2])
    # signs of the vector part from the skew part, or (near pi) relative to its largest component
    skew = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if w > 0.1:
        v = skew / (4 * w)
    else:
        k = int(np.argmax(v))
        sym = np.array([[0, R[0, 1] + R[1, 0], R[0, 2] + R[2, 0]],
                        [R[0, 1] + R[1, 0], 0, R[1, 2] + R[2, 1]],
                        [R[0, 2] + R[2, 0], R[1, 2] + R[2, 1], 0]])
        signs = np.sign(sym[k])
        signs[k] = 1.0
        v = v * signs
        if skew[k] < 0:
            v = -v
    s = np.linalg.norm(v)
    if s < 1e-15:
        return np.zeros(3)
    return 2 * math.atan2(s, w) * v / s


def skew3(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def se3_left_error(R_true, t_true, R_est, t_est):
    """xi = (rho, phi) = log(T_true T_est^-1): T_true = exp(xi^) T_est, the twist led_pose's covariance is of.
    First order this is phi = rotvec(R_true R_est'), rho = (t_true - t_est) - phi x t_est."""
    dR = R_true @ R_est.T
    phi = rotvec(dR)
    th = np.linalg.norm(phi)
    P = skew3(phi)
    if th < 1e-6:
        c = 1.0 / 12.0
    else:
        c = (1 - th * math.sin(th) / (2 * (1 - math.cos(th)))) / (th * th)
    V_inv = np.eye(3) - 0.5 * P + c * (P @ P)
    rho = V_inv @ (t_true - dR @ t_est)
    return np.concatenate([rho, phi])


def quadratic_form(x, cov):
    try:
        return float(x @ np.linalg.solve(cov, x))
    except np.linalg.LinAlgError:
        return float(x @ np.linalg.pinv(cov) @ x)


# ---------------------------------------------------------------- measuring


def mode_arguments(mode, seq):
    if mode == "single":
        return []
    args = []
    for part in mode.split("+"):
        args += ["--fuse"] if part == "fuse" else ["--attitude", os.path.join(seq.dir, "attitude.jsonl")]
    return args


def run_led_pose(a, seq, mode, truth):
    cmd = [a.led_pose, seq.dir, "--jsonl", "--constellation", os.path.abspath(seq.constellation)]
    cmd += mode_arguments(mode, seq) + (["--no-depth"] if a.no_depth else [])
    r = run(cmd)
    if r.returncode != 0:
        raise ToolFailure("led_pose failed on %s in mode %s (exit %d): %s" %
                          (seq.label, mode, r.returncode, last_line(r)), 2 if r.returncode == 2 else 3)
    os.makedirs(seq.out_dir, exist_ok=True)
    kept = os.path.join(seq.out_dir, mode + ("-no-depth" if a.no_depth else "") + ".jsonl")
    with open(kept + ".tmp", "w") as f:
        f.write(r.stdout)
    os.replace(kept + ".tmp", kept)
    poses = {}
    for number, line in enumerate(r.stdout.splitlines(), 1):
        if not line.strip():
            continue
        try:
            p = json.loads(line)
            poses[p["frame"]] = p
        except (ValueError, KeyError, TypeError):
            raise ToolFailure("led_pose %s, mode %s: stdout line %d is not a pose line: %.80s" %
                              (seq.label, mode, number, line))
    records = []
    for g in truth:
        p = poses.get(g["frame"], {"ok": False, "reason": "no output line"})
        R_true, t_true = qmat(g["q"]), np.array(g["t"], float)
        rec = {"sequence": seq.label, "constellation": seq.name, "seed": seq.seed, "variant": seq.variant,
               "mode": mode, "frame": g["frame"], "distance_m": float(np.linalg.norm(t_true)),
               "ok": bool(p.get("ok")), "reason": p.get("reason"), "ms": p.get("ms")}
        if rec["ok"]:
            R_est, t_est = qmat(p["q"]), np.array(p["t"], float)
            rec["pos_err_m"] = float(np.linalg.norm(t_est - t_true))
            rec["rot_err_rad"] = float(np.linalg.norm(rotvec(R_true @ R_est.T)))
            sigma = p.get("sigma") or [math.nan, math.nan]
            rec["sigma_pos_m"], rec["sigma_rot_rad"] = float(sigma[0]), float(sigma[1])
            rec["reproj_px"] = p.get("reproj_px")
            rec["leds"], rec["blobs"] = p.get("leds"), p.get("blobs")
            cov = p.get("covariance")
            if cov is not None:
                C = np.array(cov, float).reshape(6, 6)
                C = 0.5 * (C + C.T)
                xi = se3_left_error(R_true, t_true, R_est, t_est)
                rec["nees"] = quadratic_form(xi, C)
                rec["nees_rho"] = quadratic_form(xi[:3], C[:3, :3])
                rec["nees_phi"] = quadratic_form(xi[3:], C[3:, 3:])
        records.append(rec)
    return records


def measure_sequence(a, seq, log):
    t0 = time.time()
    rendered = False
    if not seq.complete():
        seq.render(a)
        rendered = True
    t_render = time.time() - t0
    with open(os.path.join(seq.dir, "ground_truth.jsonl")) as f:
        truth = [json.loads(line) for line in f if line.strip()]
    records, times = [], []
    for mode in a.mode_list:
        t1 = time.time()
        records += run_led_pose(a, seq, mode, truth)
        times.append("%s %.0f s" % (mode, time.time() - t1))
    if a.discard_frames:
        shutil.rmtree(seq.dir, ignore_errors=True)
    log("%s: %s; led_pose %s" % (seq.label, "rendered in %.0f s" % t_render if rendered else "cached",
                                 ", ".join(times)))
    return records


# ---------------------------------------------------------------- figures


def is_wrong(r):
    return r["pos_err_m"] > SUCCESS_POS_M or r["rot_err_rad"] > SUCCESS_ROT_RAD


def is_dangerous(r):
    if not (r["ok"] and is_wrong(r)):
        return False
    sp, sr = r["sigma_pos_m"], r["sigma_rot_rad"]
    # a missing sigma warns about nothing
    return not (sp <= math.inf and sr <= math.inf) or r["pos_err_m"] > 3 * sp or r["rot_err_rad"] > 3 * sr


def figures(records):
    n = len(records)
    ok = [r for r in records if r["ok"]]
    success = [r for r in ok if not is_wrong(r)]
    out = {"frames": n, "ok": len(ok), "success": len(success),
           "ok_fraction": len(ok) / n if n else None, "success_fraction": len(success) / n if n else None,
           "wrong_ok": sum(1 for r in ok if is_wrong(r)), "dangerous": sum(1 for r in ok if is_dangerous(r)),
           "paper_success": sum(1 for r in ok if r.get("reproj_px") is not None
                                and r["reproj_px"] <= PAPER_REPROJ_PX)}
    out["paper_success_fraction"] = out["paper_success"] / n if n else None
    ms = [r["ms"] for r in records if isinstance(r.get("ms"), (int, float))]
    out["ms_median"] = float(np.median(ms)) if ms else None
    for key in ("pos_err_m", "rot_err_rad"):
        vals = [r[key] for r in success]
        out[key + "_median_success"] = float(np.median(vals)) if vals else None
    nees = [r["nees"] for r in ok if "nees" in r]
    out["nees_frames"] = len(nees)
    if nees:
        out["nees_mean"] = float(np.mean(nees))
        out["nees_median"] = float(np.median(nees))
        out["nees_beyond_999_fraction"] = sum(1 for v in nees if v > CHI2_6_999) / len(nees)
        out["nees_rho_mean"] = float(np.mean([r["nees_rho"] for r in ok if "nees" in r]))
        out["nees_phi_mean"] = float(np.mean([r["nees_phi"] for r in ok if "nees" in r]))
        ns = [r["nees"] for r in success if "nees" in r]
        out["nees_mean_success"] = float(np.mean(ns)) if ns else None
    out["not_ok_reasons"] = dict(collections.Counter(r["reason"] or "?" for r in records if not r["ok"])
                                 .most_common())
    return out


def band_of(distance):
    for name, lo, hi in BANDS:
        if lo <= distance < hi:
            return name
    return BANDS[-1][0]


def grouped(records, key):
    groups = collections.OrderedDict()
    for r in records:
        groups.setdefault(key(r), []).append(r)
    return groups


def by_band(records):
    out = collections.OrderedDict((name, figures([r for r in records if band_of(r["distance_m"]) == name]))
                                  for name, _, _ in BANDS)
    out["all"] = figures(records)
    return out


def frac(x):
    return "–" if x is None else "%.3f" % x


def num(x, fmt):
    return "–" if x is None else fmt % x


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def report(a, summary, dangerous):
    out = []
    bands = [name for name, _, _ in BANDS] + ["all"]
    has_nees = any(f["nees_frames"] for m in summary["modes"].values() for f in m.values())
    header = ["mode", "band [m]", "frames", "ok", "success", "wrong-ok", "dangerous", "paper success"]
    if has_nees:
        header += ["NEES mean (ρ / φ)", "NEES > 22.458"]
    header += ["pos / rot err median (success)", "ms median"]
    rows = []
    for mode, per_band in summary["modes"].items():
        for band in bands:
            f = per_band[band]
            row = [mode, band, f["frames"], frac(f["ok_fraction"]), "**%s**" % frac(f["success_fraction"]),
                   f["wrong_ok"], ("**%d**" % f["dangerous"]) if f["dangerous"] else "0",
                   frac(f["paper_success_fraction"])]
            if has_nees:
                row += ["%.2f (%.2f / %.2f)" % (f["nees_mean"], f["nees_rho_mean"], f["nees_phi_mean"])
                        if f["nees_frames"] else "–",
                        frac(f.get("nees_beyond_999_fraction")) if f["nees_frames"] else "–"]
            row += ["%s m / %s rad" % (num(f["pos_err_m_median_success"], "%.4f"),
                                       num(f["rot_err_rad_median_success"], "%.4f")),
                    num(f["ms_median"], "%.3f")]
            rows.append(row)
    out += ["### By mode and distance band", "", table(header, rows), ""]
    if not has_nees:
        out += ["(no NEES: this led_pose prints no \"covariance\")", ""]

    reasons = sorted({k for m in summary["modes"].values() for f in m.values() for k in f["not_ok_reasons"]})
    if reasons:
        rows = [[mode, band, f["frames"] - f["ok"]] + [f["not_ok_reasons"].get(k, 0) for k in reasons]
                for mode, per_band in summary["modes"].items() for band, f in per_band.items()]
        out += ["### Frames without a pose, by reason", "", table(["mode", "band [m]", "not ok"] + reasons, rows), ""]

    for title, part in (("By constellation", "constellations"), ("By renderer variant", "variants")):
        rows = []
        for name, per_mode in summary[part].items():
            for mode, per_band in per_mode.items():
                f = per_band["all"]
                top = ", ".join("%s %d" % kv for kv in list(f["not_ok_reasons"].items())[:2]) or "–"
                rows.append([name, mode, f["frames"]] + [frac(per_band[b]["success_fraction"]) for b in bands] +
                            [f["wrong_ok"], f["dangerous"], top])
        out += ["### %s: success" % title, "",
                table([part[:-1], "mode", "frames"] + ["success %s" % b for b in bands] +
                      ["wrong-ok", "dangerous", "no pose, top reasons"], rows), ""]

    if dangerous:
        rows = [[d["mode"], d["sequence"], d["frame"], "%.2f" % d["distance_m"], "%.3f" % d["pos_err_m"],
                 "%.3f" % d["rot_err_rad"], "%.4f" % d["sigma_pos_m"], "%.4f" % d["sigma_rot_rad"],
                 num(d.get("nees"), "%.0f"), d.get("leds"), d.get("blobs"), d.get("reproj_px")]
                for d in dangerous[:a.list]]
        out += ["### Dangerous frames (%d): wrong by > 0.1 m or 0.1 rad and beyond 3 sigma" % len(dangerous), "",
                table(["mode", "sequence", "frame", "distance [m]", "pos err [m]", "rot err [rad]", "σ pos [m]",
                       "σ rot [rad]", "NEES", "leds", "blobs", "reproj [px]"], rows), ""]
        if len(dangerous) > a.list:
            out += ["... and %d more (all in --json)" % (len(dangerous) - a.list), ""]
    else:
        out += ["No dangerous frames.", ""]
    return "\n".join(out)


def write_json_atomically(path, data):
    tmp = "%s.tmp%d" % (path, os.getpid())
    with open(tmp, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    os.replace(tmp, path)


# ---------------------------------------------------------------- main


def main():
    a = arguments()
    a.led_pose = os.path.abspath(a.led_pose)
    a.work = os.path.abspath(a.work)
    version = check_led_pose(a.led_pose, a.mode_list)
    if not os.path.isfile(a.renderer):
        missing_tool("the renderer %s does not exist: pass --renderer" % a.renderer, a)
    a.renderer_sha = file_sha(a.renderer)
    if a.json:
        parent = os.path.dirname(os.path.abspath(a.json))
        if not os.path.isdir(parent):
            die("--json %s: the folder %s does not exist" % (a.json, parent))
    try:
        os.makedirs(a.work, exist_ok=True)
    except OSError as e:
        die("--work %s: %s" % (a.work, e.strerror))

    sequences = []
    for c in a.constellations:
        leds = read_constellation(c)
        for k, seed in enumerate(a.seed_list):
            flags = [f for f in FLAGS if getattr(a, f) or (a.mix and f in MIX[k % len(MIX)])]
            sequences.append(Sequence(a, c, leds, seed, flags))
    if any(not s.complete() for s in sequences):
        check_renderer(a)

    # led_pose refuses an invalid constellation file (exit 2): try every file on a 2-frame render before the
    # long renders start.
    for c in a.constellations:
        probe = Sequence(a, c, read_constellation(c), 1, [])
        probe.frames, probe.key = 2, dict(probe.key, frames=2)
        probe.dir = os.path.join(a.work, "probe", os.path.basename(os.path.dirname(probe.dir)))
        probe.out_dir = probe.dir + ".out"
        try:
            if not probe.complete():
                check_renderer(a)
                probe.render(a)
            with open(os.path.join(probe.dir, "ground_truth.jsonl")) as f:
                run_led_pose(a, probe, "single", [json.loads(line) for line in f if line.strip()])
        except ToolFailure as e:
            if e.code == 2:  # led_pose's own one-line message names the file and what is wrong
                detail = str(e).split("): ", 1)[-1]
                die("led_pose rejects %s: %s" % (c, detail[len("led_pose: "):] if detail.startswith("led_pose: ")
                                                 else detail))
            die(str(e), e.code)

    lock = threading.Lock()
    done = [0]

    def log(message):
        with lock:
            done[0] += 1
            print("[%d/%d] %s" % (done[0], len(sequences), message), file=sys.stderr, flush=True)

    t0 = time.time()
    records = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        futures = [pool.submit(measure_sequence, a, s, log) for s in sequences]
        try:
            for fut in futures:  # in submission order: the records' order does not depend on --jobs
                records += fut.result()
        except ToolFailure as e:
            for fut in futures:
                fut.cancel()
            stop_children()
            die(str(e), e.code)
        except Exception as e:  # anything else (a full disk, a renderer that wrote no ground truth): one line too
            for fut in futures:
                fut.cancel()
            stop_children()
            die("%s: %s" % (type(e).__name__, e), 3)

    summary = {
        "command": " ".join([PROG] + sys.argv[1:]), "led_pose": a.led_pose, "led_pose_version": version,
        "renderer": a.renderer, "renderer_sha256": a.renderer_sha, "frames": a.frames, "seeds": a.seed_list,
        "constellations": [os.path.relpath(os.path.abspath(c), REPO) for c in a.constellations],
        "sequences": [{"sequence": s.label, "dir": s.dir, "flags": list(s.flags)} for s in sequences],
        "modes_run": a.mode_list, "no_depth": a.no_depth,
        "rules": {"success": "ok and pos err <= 0.1 m and rot err <= 0.1 rad",
                  "wrong_ok": "ok and (pos err > 0.1 m or rot err > 0.1 rad)",
                  "dangerous": "wrong_ok and (pos err > 3 sigma_pos or rot err > 3 sigma_rot)",
                  "paper_success": "ok and reproj_px <= 10",
                  "nees": "xi' C^-1 xi, xi = log(T_true T_est^-1) = (rho, phi); bound chi2(6) 99.9 %% = %g" %
                          CHI2_6_999,
                  "bands_m": {name: [lo, hi if hi < math.inf else None] for name, lo, hi in BANDS}},
        "wall_s": round(time.time() - t0, 1),
    }
    summary["modes"] = collections.OrderedDict(
        (mode, by_band(rs)) for mode, rs in grouped(records, lambda r: r["mode"]).items())
    for part, key in (("constellations", "constellation"), ("variants", "variant")):
        summary[part] = collections.OrderedDict(
            (name, collections.OrderedDict((mode, by_band(ms)) for mode, ms in
                                           grouped(rs, lambda r: r["mode"]).items()))
            for name, rs in grouped(records, lambda r, k=key: r[k]).items())
    # grouped by mode (stable: sequences and frames stay in order within a mode)
    dangerous = sorted((r for r in records if r["ok"] and is_dangerous(r)), key=lambda r: a.mode_list.index(r["mode"]))
    summary["dangerous_frames"] = dangerous
    summary["wrong_ok_frames"] = [r for r in records if r["ok"] and is_wrong(r)]

    print("## led_pose on the independent renderer's sequences\n")
    print("%s; %d sequences x %d frames (%s; seeds %s), modes %s%s\n" % (
        version or a.led_pose, len(sequences), a.frames,
        ", ".join(os.path.splitext(os.path.basename(c))[0] for c in a.constellations), a.seeds,
        ", ".join(a.mode_list), ", no depth" if a.no_depth else ""))
    print(report(a, summary, dangerous))
    if a.json:
        write_json_atomically(a.json, summary)
    return check_requirements(a, records)


def check_requirements(a, records):
    """--require-*: 1 (with one line per figure that misses) when a mode misses a floor or ceiling, else 0."""
    failures = []
    by_mode = grouped(records, lambda r: r["mode"])
    for mode in a.mode_list:
        rs = by_mode.get(mode, [])
        every, near = figures(rs), figures([r for r in rs if r["distance_m"] < 2.0])
        if not rs:
            failures.append("%s: no frames measured" % mode)
            continue
        if a.require_success_2m is not None and not near["frames"]:
            failures.append("%s: no frames within 2 m to check --require-success-2m on" % mode)
        if a.require_dangerous is not None and every["dangerous"] > a.require_dangerous:
            failures.append("%s: %d dangerous frames, at most %d allowed" % (mode, every["dangerous"],
                                                                             a.require_dangerous))
        if a.require_success is not None and (every["success_fraction"] or 0) < a.require_success:
            failures.append("%s: success %.3f over all %d frames, below %.3f" % (
                mode, every["success_fraction"] or 0, every["frames"], a.require_success))
        if a.require_success_2m is not None and near["frames"] and near["success_fraction"] < a.require_success_2m:
            failures.append("%s: success %.3f over the %d frames within 2 m, below %.3f" % (
                mode, near["success_fraction"], near["frames"], a.require_success_2m))
    for f in failures:
        print("%s: FAILED %s" % (PROG, f), file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
