"""Motion Matching: the paper's database-search baseline, for either dancer.

The paper's MM "directly searches for the next pose within the training dataset, using the root
trajectories T(0->+1) of both characters and the poses P of both as query features". Here:

Database   every valid frame t of the training takes (phase 0 of the 120 fps files, unmirrored and
           mirrored), all features in the root space of the dancer being predicted ("self").
Features   groups, each divided by its own std (one number per group) and scaled by a weight,
           as in orangeduck's Motion-Matching:
             follower: the leader's future root path (positions, directions), the follower's own
                       future root path (positions, directions), the leader's joint positions
                       and velocities, the follower's joint positions and velocities;
             leader:   its own future path (the control), its own pose, the follower's pose.
           Groups have very different sizes (12 numbers for a path, 51 for a pose), so each is
           also divided by sqrt(its size): every group then adds about the same to a distance
           and the weights mean what they say.
Result     the database's output vector O (323) at the matched frame: the recorded next frame.

The follower's own future is not in the model input (the networks never see it). At query time
it comes from `self_future`:
  "plan"        the future path of the previous match (the output's trajectory_future, which is in
                the root space the next query is made in): MM's usual bias to keep playing the
                clip it is in. The first query after reset() extrapolates.
  "extrapolate" the follower's velocity over its last 10 frames, carried on for a second, facing
                ahead. Stateless; used for teacher-forced (batched) evaluation.
A caller may also pass the true future (evaluate's "oracle" row, like the paper's MM query).

Search: brute force, or bounding boxes over blocks of 64 and 16 consecutive frames (orangeduck)
followed by a per-row bound on the leading principal axes (see BoundingBoxes): a lower bound on
the distance prunes a box or row once a real frame is closer. Both return the same frame (lowest
index on ties); the accelerated one is several times faster on the CMU database (--bench).
`MotionMatching` is called like rollout.OnnxPolicy:
policy(x [B, 660], temperature, rng) -> {"output": [B, 323], "index": [B]}.

    python -m training.evaluation.motion_matching --bench      # query time, brute force vs bounding boxes
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from ..mirror import features as feat
from ..data.dataset import (TEST_TAKES, VALIDATION_TAKES, DataError, discover_takes,
                      load_pair, pair_tracks, select_takes)
from ..data.folders import add_folder
from ..data.led_figures import figure_spans
from ..mirror.features import FUTURE_OFFSETS, KEYS, Track, output_features, trajectory_block, valid_frames

FOLLOWER_IN = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)
LEADER_IN = feat.block_slices(feat.LEADER_INPUT_LAYOUT)
OUT = feat.block_slices(feat.OUTPUT_LAYOUT)

# (group, weight). Paths: 6 keys x (x, z) or (fwd x, fwd z); poses: 17 joints x 3.
FOLLOWER_GROUPS = [("partner_future_position", 1.0), ("partner_future_direction", 1.0),
                   ("self_future_position", 1.0), ("self_future_direction", 1.0),
                   ("partner_position", 1.0), ("partner_velocity", 1.0),
                   ("self_position", 1.0), ("self_velocity", 1.0)]
LEADER_GROUPS = [("self_future_position", 1.0), ("self_future_direction", 1.0),
                 ("partner_position", 1.0), ("partner_velocity", 1.0),
                 ("self_position", 1.0), ("self_velocity", 1.0)]
SMALL_BOX, LARGE_BOX = 16, 64
EXTRAPOLATE_FRAMES = 10   # the past span (frames) whose mean velocity the extrapolation carries on


# ---------------------------------------------------------------- features

def _path_parts(path: np.ndarray):
    """Trajectory block [B, 24] -> key positions [B, 12] and key directions [B, 12]."""
    k = path.reshape(-1, KEYS, 4)
    return k[..., :2].reshape(-1, 2 * KEYS), k[..., 2:].reshape(-1, 2 * KEYS)


def _pose_parts(pose: np.ndarray):
    """Pose block [B, 204] -> joint positions [B, 51] and velocities [B, 51]."""
    p = pose.reshape(-1, feat.N_JOINTS, 12)
    return p[..., 0:3].reshape(-1, 3 * feat.N_JOINTS), p[..., 3:6].reshape(-1, 3 * feat.N_JOINTS)


def extrapolate_future(x: np.ndarray, role: str = "follower") -> np.ndarray:
    """Own future path [B, 24] guessed from the own past path in the input: the mean velocity of
    the last EXTRAPOLATE_FRAMES frames carried on, facing straight ahead (root space)."""
    past = x[:, (FOLLOWER_IN if role == "follower" else LEADER_IN)["self_trajectory_past"]]
    past = past.reshape(-1, KEYS, 4)
    key = KEYS - EXTRAPOLATE_FRAMES // feat.KEY_STEP          # the past key EXTRAPOLATE_FRAMES back
    velocity = -past[:, key, :2] / EXTRAPOLATE_FRAMES          # root is at the origin now
    out = np.zeros((len(x), KEYS, 4))
    out[..., :2] = velocity[:, None] * FUTURE_OFFSETS[None, :, None]
    out[..., 3] = 1.0                                          # forward = +Z in root space
    return out.reshape(len(x), -1)


def query_features(x: np.ndarray, self_future: np.ndarray, role: str) -> np.ndarray:
    """Raw (un-normalized) query [B, D] from the model input [B, 660] and the own future path
    [B, 24], groups in the order of FOLLOWER_GROUPS / LEADER_GROUPS."""
    x = np.atleast_2d(x).astype(np.float64)
    if role == "follower":
        sl = FOLLOWER_IN
        parts = [*_path_parts(x[:, sl["partner_trajectory_future"]]), *_path_parts(self_future)]
    else:
        sl = LEADER_IN
        parts = [*_path_parts(x[:, sl["control"]])]
    parts += [*_pose_parts(x[:, sl["partner_pose"]]), *_pose_parts(x[:, sl["self_pose"]])]
    return np.concatenate(parts, -1)


def group_sizes(role: str) -> list[int]:
    path, pose = 2 * KEYS, 3 * feat.N_JOINTS
    return ([path] * 4 if role == "follower" else [path] * 2) + [pose] * 4


def own_future(me: Track, frames: np.ndarray) -> np.ndarray:
    """The dancer's own future root path at t, in its root space at t [N, 24]."""
    idx = frames[:, None] + FUTURE_OFFSETS[None]
    return trajectory_block(me.root[idx], me.heading[idx], me.root[frames], me.heading[frames])


def database_arrays(lead: Track, follow: Track, role: str):
    """One take's database rows: model input [N, 660], own future [N, 24], output [N, 323]."""
    frames = valid_frames(lead.frames)
    figure = feat.figure_block(figure_spans(lead.positions, follow.positions), frames)
    if role == "follower":
        me, x = follow, feat.follower_input(lead, follow, frames, figure)
    else:
        me, x = lead, feat.leader_input(follow, lead, frames, figure)
    return x, own_future(me, frames), output_features(me, frames)


# ---------------------------------------------------------------- search

class BoundingBoxes:
    """Exact nearest-row search: orangeduck's bounding boxes, then a bound per row.

    The rows are stored rotated onto their principal axes (MotionMatching does this: a rotation,
    so distances are unchanged, and brute force searches the same rotated rows, so both see
    identical numbers). Every bound below looks at the leading `project` axes only: dropping
    axes can only shrink a squared distance, so each is a true lower bound, and 32 of 252 axes
    carry ~90% of the variance here, so they are tight and 8x cheaper than all axes.
      1. boxes around 64 consecutive rows, then the 16-row boxes inside the survivors: the
         squared distance from the query to the box (consecutive frames of a clip are close, so
         boxes are tight for queries near the data; far from it they prune less);
      2. each surviving row's own distance over those axes;
      3. the full distance for what is left.
    A stage drops what cannot beat the best real row found so far. Rows keep database order
    through every stage, so ties resolve to the lowest row, as in brute force.
    """

    def __init__(self, db: np.ndarray, small: int = SMALL_BOX, large: int = LARGE_BOX, project: int = 32):
        assert large % small == 0
        self.db, self.small, self.large = db, small, large
        self.n, self.per_large = len(db), large // small
        self.project = min(project, db.shape[1])
        lead = self.lead = np.ascontiguousarray(db[:, :self.project])
        s_starts, l_starts = np.arange(0, self.n, small), np.arange(0, self.n, large)
        self.small_lo, self.small_hi = np.minimum.reduceat(lead, s_starts), np.maximum.reduceat(lead, s_starts)
        self.large_lo, self.large_hi = np.minimum.reduceat(lead, l_starts), np.maximum.reduceat(lead, l_starts)

    @staticmethod
    def _box_bound(q, lo, hi):
        gap = np.maximum(np.maximum(lo - q, q - hi), 0.0)
        return np.einsum("ij,ij->i", gap, gap)

    def _distance(self, rows, q):
        d = self.db[rows] - q
        return np.einsum("ij,ij->i", d, d)

    @staticmethod
    def _keep(bound):
        # <= plus a hair: a row tied with the best, or a bound that only rounding lifts above it,
        # is never dropped.
        return bound * (1 + 1e-9) + 1e-12

    def nearest(self, q: np.ndarray) -> tuple[int, float]:
        qp = q[:self.project]
        lb_large = self._box_bound(qp, self.large_lo, self.large_hi)
        # A first upper bound from a real row: the best one in the most promising large box.
        first = int(np.argmin(lb_large))
        bound = float(self._distance(np.arange(first * self.large, min((first + 1) * self.large, self.n)), q).min())
        large = np.flatnonzero(lb_large <= self._keep(bound))
        small = (large[:, None] * self.per_large + np.arange(self.per_large)).ravel()
        small = small[small * self.small < self.n]
        small = small[self._box_bound(qp, self.small_lo[small], self.small_hi[small]) <= self._keep(bound)]
        rows = (small[:, None] * self.small + np.arange(self.small)).ravel()
        rows = rows[rows < self.n]
        d = self.lead[rows] - qp
        lb_rows = np.einsum("ij,ij->i", d, d)
        # Tighten the bound with the row that looks best so far, then finish the rest exactly.
        bound = min(bound, float(self._distance(rows[np.argmin(lb_rows)][None], q)[0]))
        rows = rows[lb_rows <= self._keep(bound)]
        dist = self._distance(rows, q)
        i = int(np.argmin(dist))
        return int(rows[i]), float(dist[i])


def brute_force(db: np.ndarray, q: np.ndarray) -> tuple[int, float]:
    d = db - q
    dist = np.einsum("ij,ij->i", d, d)
    i = int(np.argmin(dist))
    return i, float(dist[i])


# ---------------------------------------------------------------- the policy

class MotionMatching:
    """Database search as a step policy: same call as rollout.OnnxPolicy."""

    def __init__(self, inputs: np.ndarray, futures: np.ndarray, outputs: np.ndarray, role: str = "follower",
                 weights: dict[str, float] | None = None, self_future: str = "plan",
                 accelerated: bool = True):
        if role not in ("follower", "leader"):
            raise ValueError(f"role must be follower or leader, not {role!r}")
        if self_future not in ("plan", "extrapolate"):
            raise ValueError(f"self_future must be plan or extrapolate, not {self_future!r}")
        self.role, self.self_future, self.accelerated = role, self_future, accelerated
        groups = FOLLOWER_GROUPS if role == "follower" else LEADER_GROUPS
        w = dict(groups)
        w.update(weights or {})
        raw = query_features(inputs, futures, role)
        self.mean = raw.mean(0)
        # One scale per group: its mean per-dimension std, times sqrt(size) (see the module doc),
        # over the weight. Same treatment for every row and every query.
        self.scale = np.empty(raw.shape[1])
        start = 0
        for (name, _), n in zip(groups, group_sizes(role)):
            std = max(float(raw[:, start:start + n].std(0).mean()), 1e-6)
            self.scale[start:start + n] = std * np.sqrt(n) / max(w[name], 1e-9)
            start += n
        # Principal axes of the scaled rows, largest variance first: a rotation, so distances are
        # those of the scaled features; the search index bounds with the leading axes.
        scaled = (raw - self.mean) / self.scale
        _, vectors = np.linalg.eigh(np.cov(scaled.T))
        self.axes = np.ascontiguousarray(vectors[:, ::-1])
        self.db = scaled @ self.axes
        self.outputs = outputs.astype(np.float32)
        self.boxes = BoundingBoxes(self.db)
        self.plan: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.db)

    def reset(self) -> None:
        """Forget the previous match (a new rollout starts)."""
        self.plan = None

    def normalize(self, raw: np.ndarray) -> np.ndarray:
        """Raw query features [..., D] -> the database's scaled, rotated space."""
        return ((raw - self.mean) / self.scale) @ self.axes

    def search(self, q: np.ndarray) -> int:
        return (self.boxes.nearest(q) if self.accelerated else brute_force(self.db, q))[0]

    def __call__(self, x, temperature: float = 0.0, rng=None, self_future=None) -> dict:
        """Nearest database frame for each row of x [B, 660]; temperature and rng are ignored
        (the search is deterministic). self_future [B, 24] overrides the own future path."""
        x = np.atleast_2d(x)
        if self_future is None:
            if self.role == "leader":
                self_future = x[:, LEADER_IN["control"]]
            elif self.self_future == "plan" and self.plan is not None and len(self.plan) == len(x):
                self_future = self.plan
            else:
                self_future = extrapolate_future(x)
        q = self.normalize(query_features(x, np.atleast_2d(self_future), self.role))
        index = np.array([self.search(row) for row in q])
        out = self.outputs[index]
        self.plan = out[:, OUT["trajectory_future"]].astype(np.float64)
        return {"output": out, "index": index}


# ---------------------------------------------------------------- building from takes

def training_takes(data, exclude=(), leader: str | None = None, names: list[str] | None = None):
    """The takes a database (or the evaluation encoder) may use: all takes of `data` except the
    validation and test takes of dataset.py and anything in `exclude`, or exactly `names`."""
    takes = discover_takes(data, leader)
    if names:
        takes = select_takes(takes, names)
    else:
        skip = set(VALIDATION_TAKES) | set(TEST_TAKES) | set(exclude)
        takes = [t for t in takes if t.name not in skip]
    takes = [t for t in takes if t.name not in set(exclude)]
    if not takes:
        raise DataError(f"{data}: no training takes left for the database")
    return takes


def load_tracks(takes, mirror: bool = True) -> list[tuple[Track, Track]]:
    """(leader, follower) Tracks at 30 fps, phase 0, unmirrored and (optionally) mirrored."""
    out = []
    for take in takes:
        lead, follow = load_pair(take)
        for m in ((False, True) if mirror else (False,)):
            out.append(pair_tracks(lead, follow, 0, m))
    return out


def build(tracks: list[tuple[Track, Track]], role: str = "follower", **kwargs) -> MotionMatching:
    parts = [database_arrays(lead, follow, role) for lead, follow in tracks]
    x, fut, y = (np.concatenate([p[i] for p in parts]) for i in range(3))
    return MotionMatching(x, fut, y, role, **kwargs)


# ---------------------------------------------------------------- benchmark

def bench(mm: MotionMatching, queries: np.ndarray) -> dict:
    """Time both searches on the same normalized queries [Q, D]; check they agree."""
    t0 = time.perf_counter()
    brute = [brute_force(mm.db, q)[0] for q in queries]
    t1 = time.perf_counter()
    boxed = [mm.boxes.nearest(q)[0] for q in queries]
    t2 = time.perf_counter()
    n = len(queries)
    return {"rows": len(mm), "dims": mm.db.shape[1], "queries": n,
            "brute_ms": 1e3 * (t1 - t0) / n, "boxes_ms": 1e3 * (t2 - t1) / n,
            "speedup": (t1 - t0) / max(t2 - t1, 1e-12), "agree": int(sum(a == b for a, b in zip(brute, boxed)))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.motion_matching", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", action="store_true", help="time brute force vs bounding boxes")
    add_folder(ap, "data", "the training takes are the database, the test takes the queries")
    ap.add_argument("--role", default="follower", choices=["follower", "leader"])
    ap.add_argument("--queries", type=int, default=300, help="queries from the test takes")
    args = ap.parse_args(argv)
    if not args.bench:
        ap.error("nothing to do: pass --bench")
    try:
        t0 = time.perf_counter()
        tracks = load_tracks(training_takes(args.data))
        mm = build(tracks, args.role)
        t_build = time.perf_counter() - t0
        # Queries a rollout would make: test-take frames, own future extrapolated from the past.
        tests = [t for t in discover_takes(args.data) if t.name in TEST_TAKES] or discover_takes(args.data)[:1]
        x = np.concatenate([database_arrays(*pair_tracks(*load_pair(t)), args.role)[0] for t in tests])
    except DataError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    rows = np.random.default_rng(0).choice(len(x), min(args.queries, len(x)), replace=False)
    fut = extrapolate_future(x[rows]) if args.role == "follower" else x[rows][:, LEADER_IN["control"]]
    q = mm.normalize(query_features(x[rows], fut, args.role))
    r = bench(mm, q)
    print(f"{args.role} database: {r['rows']} frames x {r['dims']} features (built in {t_build:.1f} s)")
    print(f"brute force    {r['brute_ms']:.3f} ms/query")
    print(f"bounding boxes {r['boxes_ms']:.3f} ms/query  ({SMALL_BOX}/{LARGE_BOX}-frame boxes)")
    print(f"speedup {r['speedup']:.1f}x; same frame in {r['agree']}/{r['queries']} queries")
    return 0 if r["agree"] == r["queries"] else 1


if __name__ == "__main__":
    sys.exit(main())
