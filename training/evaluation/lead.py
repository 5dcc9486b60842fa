"""python -m training.evaluation.lead: does the visitor's "lead a turn" work, and does the couple dance
when nobody steers? -> lead.json + lead.md

    python -m training.evaluation.lead --models public/models --seeds 100 --out runs/lead

Two measurements on the shipped models, the dancers run as the page runs them (options.py):

1. Requests. Each seed dances a duet with nobody steering and, unless --figures 1, no figures of
   his own (the page's ?figures=0); every REQUEST_EVERY seconds the duet is copied and the copy is
   asked to lead her turn (rollout.ask_turn, a random way), while the original goes on unasked.
   Both are danced REQUEST_SECONDS on with the same random stream and the follower's turns are
   counted (figures.turns, from the request on): a request works when the follower completes a
   turn in that time, and the same moment unasked tells how often she would have turned anyway.
   Both dancers read the figure being led (features.figure_block); she gets no command to act.
2. Unasked dancing. The same duets, before any copy: each dancer's turns per minute, spin frames,
   body motion and travel (figures.py) against the recorded dancers of --takes, and how far the
   leader goes from where he started (the couple must stay on screen).
"""
from __future__ import annotations

import argparse
import copy
import json
import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..data.dataset import DataError, TEST_TAKES
from ..data.folders import add_folder
from ..mirror.rollout import NOW, ask_turn, start_duet, step
from ..mirror import features as feat
from ..mirror.skeleton import FPS, HANDS
from . import figures as Fg
from .figures import HAND_RAISED
from . import turn_cues as C
from . import options as O
from .evaluate_inputs import EvalError, find_models, load_eval_takes, load_onnx

# The lead detector (turn_cues, his body alone) says a turn will complete this long after what it
# reads: he leads it by then (it finds 52 % of the recorded turns at 0.5 s, chance 18 %; 1.5 s
# ahead, before her turn has begun, 25 %: the recorded lead comes with her turn).
LEGIBILITY_LEAD = 0.5
REQUEST_SECONDS = 4.0    # s of dance after a request in which her turn counts
REQUEST_EVERY = 7.0      # s between requests in one duet: pressed 3 s and 10 s into the dance
WARM_UP = 3.0            # s of dancing before the first request


def branch(duet, leader, follower, temperature: float, rng: np.random.Generator, direction: int | None,
           frames: int, with_body: bool = False) -> tuple[np.ndarray, np.ndarray | None, float]:
    """Dance a copy of the duet `frames` steps on (asked for a turn in `direction` first, or not):
    the follower's world positions [frames + 1, 17, 3], the request's frame first, (with_body)
    his body at each of those frames (turn_cues.leader_body: his past, pose and plan in his own
    root space; None without), the highest his hands went (m above the floor), how his higher hand
    wound (winding) and how far his own facing turned (degrees, counterclockwise seen from above)."""
    d = copy.deepcopy(duet)
    # The policies are not copied with the duet: a chooser on the count keeps a running mean of its
    # dancer's footwork (on_count.OnCount), and a branch that moved it on handed its 4 s to the
    # next branch and to the duet itself, so the unasked branch danced on after the asked one.
    kept = count_state(leader, follower)
    if direction is not None:
        ask_turn(d, direction)
    out = np.zeros((frames + 1, 17, 3))
    body = np.zeros((frames + 1, C.LEADER_BODY_SIZE)) if with_body else None
    now, hand = np.array([NOW]), 0.0
    hands = np.zeros((frames + 1, 2, 3))
    his = np.zeros((frames + 1, 17, 3))
    for f in range(frames + 1):
        if f > 0:
            step(d, leader, follower, np.zeros(2), temperature, rng)
        out[f] = d.follower.track.positions[NOW]
        his[f] = d.leader.track.positions[NOW]
        hand = max(hand, float(d.leader.track.positions[NOW][HANDS, 1].max()))
        hands[f] = feat.to_root_space_points(d.leader.track.positions[NOW][HANDS], d.leader.root, d.leader.heading)
        if with_body:
            body[f] = C.leader_body(d.follower.track, d.leader.track, now)[0]
    put_count_state(kept)
    facing = Fg.facing(his)
    return out, body, hand, winding(hands), float(np.degrees(facing[-1] - facing[0]))


def count_state(*policies) -> list[tuple[object, dict]]:
    """What each policy's chooser on the count has seen (on_count.OnCount's fields), to put back
    with put_count_state."""
    choosers = [getattr(p, "on_count", None) for p in policies]
    return [(c, dict(vars(c))) for c in choosers if c is not None]


def put_count_state(kept: list[tuple[object, dict]]) -> None:
    for chooser, fields in kept:
        vars(chooser).update(fields)


def winding(hands: np.ndarray) -> float:
    """The signed area (m²) the higher of his hands [frames, 2, 3] (his root space) sweeps over the
    floor plan: negative winds the way that leads her turn to the left (+1), as in the recording."""
    p = hands[:, int(hands[..., 1].mean(0).argmax())]
    x, z = p[:, 0] - p[:, 0].mean(), p[:, 2] - p[:, 2].mean()
    return float(0.5 * (x[:-1] * z[1:] - z[:-1] * x[1:]).sum())


def lead_seen(detector: C.Detector | None, body: np.ndarray | None, direction: int) -> bool | None:
    """Does a detector of the recorded leads (turn_cues, reading only his body) see him lead a
    turn of `direction` in these frames? Tells a leader who does not lead from a follower who
    does not follow."""
    if detector is None:
        return None
    s = {"frames": np.arange(len(body)), "body": body}
    return any(d == direction for _, d in detector.turns(s))


def request_frames(frames: int) -> set[int]:
    """The frames of a duet of `frames` at which a request is made (one every REQUEST_EVERY seconds
    after WARM_UP, each with REQUEST_SECONDS left to be danced)."""
    return set(range(int(WARM_UP * FPS), frames - int(REQUEST_SECONDS * FPS) + 1, int(REQUEST_EVERY * FPS)))


def one_duet(manifest, leader, follower, temperature: float, seed: int, seconds: float,
             detector: C.Detector | None = None, tempo: float | None = None, figures: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    O.restart_count(leader, follower)   # a seed of a run of many dances as it does alone
    duet = start_duet(manifest, tempo=tempo, figures=figures, seed=seed)
    frames = int(seconds * FPS)
    window = int(REQUEST_SECONDS * FPS)
    ask_at = request_frames(frames)
    lead, follow = np.zeros((frames, 17, 3)), np.zeros((frames, 17, 3))
    requests = []
    for f in range(frames):
        if f in ask_at:
            direction = int(rng.choice([-1, 1]))
            state = rng.bit_generator.state
            asked, body_asked, hand_asked, wind_asked, his_asked = branch(
                duet, leader, follower, temperature, np.random.default_rng(seed * 1000 + f), direction, window,
                detector is not None)
            unasked, body_unasked, hand_unasked, wind_unasked, his_unasked = branch(
                duet, leader, follower, temperature, np.random.default_rng(seed * 1000 + f), None, window,
                detector is not None)
            rng.bit_generator.state = state
            turns_asked, turns_unasked = Fg.turns(Fg.facing(asked)), Fg.turns(Fg.facing(unasked))
            requests.append({"frame": f, "direction": direction,
                             "turned": bool(turns_asked), "turned_that_way": any(d == direction for _, d in turns_asked),
                             "seconds": turns_asked[0][0] / FPS if turns_asked else None,
                             "turned_unasked": bool(turns_unasked),
                             "hand_m": hand_asked, "hand_m_unasked": hand_unasked,
                             "winding": wind_asked, "winding_unasked": wind_unasked,
                             # his own facing over the request, positive the asked way (rollout.lead_plan)
                             "his_turn": direction * his_asked, "his_turn_unasked": direction * his_unasked,
                             "hand_raised": hand_asked > HAND_RAISED, "hand_raised_unasked": hand_unasked > HAND_RAISED,
                             "lead_seen": lead_seen(detector, body_asked, direction),
                             "lead_seen_unasked": lead_seen(detector, body_unasked, direction)})
        step(duet, leader, follower, np.zeros(2), temperature, rng)
        lead[f], follow[f] = duet.leader.track.positions[NOW], duet.follower.track.positions[NOW]
    return {"seed": seed, "requests": requests, **dancing(lead, follow)}


def dancing(lead: np.ndarray, follow: np.ndarray, start: np.ndarray | None = None) -> dict:
    """figures.dancer of both dancers [frames, 17, 3] (without its per-turn lists), and the leader's
    largest distance (m) from `start` (x, z on the floor; default: where his hips are at the first frame)."""
    strip = lambda d: {k: v for k, v in d.items() if not isinstance(v, list)}
    start = lead[0, 0, [0, 2]] if start is None else np.asarray(start, float)
    return {"leader": strip(Fg.dancer(lead)), "follower": strip(Fg.dancer(follow)),
            "leader_from_start_m": float(np.linalg.norm(lead[:, 0, [0, 2]] - start, axis=-1).max())}


def unasked_duet(manifest, leader, follower, temperature: float, seed: int, seconds: float,
                 ask: tuple[float, int] | None = None, tempo: float | None = None, figures: bool = False) -> dict:
    """The duet one_duet dances for `seed`, without its request copies (the random stream is the
    same: each request's direction is still drawn): world positions [frames, 17, 3] of `leader`
    and `follower` as the networks left them (what one_duet measures) and `leader_shown`,
    `follower_shown` after the contact layer (what the page shows). To film a seed of
    this command's tables (scripts/worst_seed.py --nobody-steering). `ask` (seconds, direction):
    the duet itself is asked for a turn then (one_duet asks that request's copy at frame
    seconds * FPS, with its own random stream: the film shows the request, not the same draws)."""
    rng = np.random.default_rng(seed)
    O.restart_count(leader, follower)
    duet = start_duet(manifest, tempo=tempo, figures=figures, seed=seed)
    frames = int(seconds * FPS)
    ask_at = request_frames(frames)
    out = {k: np.zeros((frames, 17, 3)) for k in ("leader", "follower", "leader_shown", "follower_shown")}
    for f in range(frames):
        if f in ask_at:
            rng.choice([-1, 1])
        if ask is not None and f == int(round(ask[0] * FPS)):
            ask_turn(duet, ask[1])
        step(duet, leader, follower, np.zeros(2), temperature, rng)
        out["leader"][f], out["follower"][f] = duet.leader.track.positions[NOW], duet.follower.track.positions[NOW]
        out["leader_shown"][f], out["follower_shown"][f] = duet.shown
    return out


def summary(per_seed: list[dict], ref: dict) -> dict:
    req = [r for s in per_seed for r in s["requests"]]
    n = len(req)
    share = lambda k: sum(r[k] for r in req) / n if n else float("nan")
    out = {"requests": n, "turned": share("turned"), "turned_that_way": share("turned_that_way"),
           "turned_unasked": share("turned_unasked"),
           "hand_raised": share("hand_raised"), "hand_raised_unasked": share("hand_raised_unasked"),
           "median_seconds": float(np.median([r["seconds"] for r in req if r["seconds"] is not None]))
           if any(r["turned"] for r in req) else None,
           "his_turn": float(np.median([r["his_turn"] for r in req])) if n else None,
           "his_turn_unasked": float(np.median([r["his_turn_unasked"] for r in req])) if n else None}
    # The asked way of her turns, per way: a follower who turns one way whatever is asked shows here.
    for name, way in (("left", 1), ("right", -1)):
        turned = [r for r in req if r["direction"] == way and r["turned"]]
        out[f"that_way_of_turns_{name}"] = (sum(r["turned_that_way"] for r in turned) / len(turned)
                                            if turned else None)
    # Unasked, how often she turns in the windows where his hand went up and where it did not: her
    # reading of his lead (recorded_leads.windows measures the recorded follower's).
    up = [r["turned_unasked"] for r in req if r["hand_raised_unasked"]]
    down = [r["turned_unasked"] for r in req if not r["hand_raised_unasked"]]
    out["turned_unasked_hand_up"] = sum(up) / len(up) if up else None
    out["turned_unasked_hand_down"] = sum(down) / len(down) if down else None
    if n and req[0]["lead_seen"] is not None:
        out["lead_seen"], out["lead_seen_unasked"] = share("lead_seen"), share("lead_seen_unasked")
    out.update(dancing_summary(per_seed, ref))
    # The seed whose requests worked least often: the one to look at.
    by_seed = [(sum(r["turned"] for r in s["requests"]) / max(1, len(s["requests"])), s["seed"]) for s in per_seed]
    out["worst_request_seed"] = min(by_seed)[1]
    return out


def dancing_summary(per_seed: list[dict], ref: dict) -> dict:
    """Each dancer's figures pooled over seeds (dancing()), with ratios to the recording `ref` and the
    least-turning seed, and the leader's distance from his start: median and worst over seeds."""
    out = {}
    for who in ("leader", "follower"):
        items = [s[who] for s in per_seed]
        pooled = Fg.summarize(items)
        worst = min(range(len(items)), key=lambda i: items[i]["turns_per_min"])
        # The median seed too: a few seeds where the couple spins together like a top can carry the
        # pooled rate while most seeds hardly turn (one leader measured over
        # seeds 0-49: pooled 0.67x, median seed 2/min).
        out[who] = {**pooled, "ratio": Fg.ratios(pooled, ref[who]),
                    "worst_seed": per_seed[worst]["seed"], "worst_turns_per_min": items[worst]["turns_per_min"],
                    "median_turns_per_min": float(np.median([i["turns_per_min"] for i in items]))}
    far = [s["leader_from_start_m"] for s in per_seed]
    out["leader_from_start_m"] = {"median": float(np.median(far)), "max": float(np.max(far)),
                                  "worst_seed": per_seed[int(np.argmax(far))]["seed"]}
    return out


def times(value: float, reference: float) -> str:
    """value as a multiple of reference ("1.25×"); "–" where the recording has none of it (a
    recorded dancer who never turns)."""
    return f"{value / reference:.2f}×" if reference else "–"


def dancing_table(s: dict, ref: dict) -> list[str]:
    """Markdown lines of dancing_summary `s` beside the recording `ref`: the table and the leader's distance."""
    L = ["| dancer | turns/min | median seed | spin frames | body motion m/s | travel m/s | least-turning seed |",
         "|---|---|---|---|---|---|---|"]
    for who in ("leader", "follower"):
        r, q, f0 = s[who], s[who]["ratio"], ref[who]
        L.append(f"| recorded {who} | {f0['turns_per_min']:.1f} | – | {100 * f0['spin_frames']:.1f} % | "
                 f"{f0['body_motion']:.2f} | {f0['travel']:.2f} | – |")
        L.append(f"| {who} | {r['turns_per_min']:.1f} ({q['turns_per_min']:.2f}×) | "
                 f"{r['median_turns_per_min']:.1f} ({times(r['median_turns_per_min'], f0['turns_per_min'])}) | {100 * r['spin_frames']:.1f} % "
                 f"({q['spin_frames']:.2f}×) | {r['body_motion']:.2f} ({q['body_motion']:.2f}×) | {r['travel']:.2f} "
                 f"({q['travel']:.2f}×) | seed {r['worst_seed']}: {r['worst_turns_per_min']:.1f}/min |")
    far = s["leader_from_start_m"]
    return L + ["", f"The leader's largest distance from where he started: median {far['median']:.2f} m, "
                    f"worst {far['max']:.2f} m (seed {far['worst_seed']})."]


def recording(data: str, takes: list[str]) -> dict:
    tk = load_eval_takes(data, takes, None, None)
    return {who: Fg.summarize([Fg.dancer(getattr(t, part).positions) for t in tk])
            for who, part in (("leader", "lead"), ("follower", "follow"))}


def way_share(s: dict, name: str) -> str:
    v = s.get(f"that_way_of_turns_{name}")
    return "–" if v is None else f"{100 * v:.0f} %"


def write_markdown(path: Path, res: dict) -> None:
    s, ref, cfg = res["summary"], res["recording"], res["config"]
    L = [f"# Leading a turn, and dancing unasked: {cfg['seeds']} seeds × {cfg['seconds']:g} s, nobody steering", "",
         f"Models `{cfg['models']}`; leader variety {cfg['temperature']:g}, follower {cfg['follower_temperature']:g}, "
         f"guard {cfg['guard']}. Wall time {cfg['wall_seconds'] / 60:.1f} min.", "",
         "## Requests", "",
         f"{s['requests']} requests, one every {REQUEST_EVERY:g} s after {WARM_UP:g} s; each danced "
         f"{REQUEST_SECONDS:g} s asked and, from the same moment with the same random stream, unasked.", "",
         f"| follower completes a turn (300° within 2.5 s) within {REQUEST_SECONDS:g} s | share |", "|---|---|",
         f"| asked | {100 * s['turned']:.0f} % (the asked direction: {100 * s['turned_that_way']:.0f} %) |",
         f"| the same moments, unasked | {100 * s['turned_unasked']:.0f} % |",
         f"| ratio asked / unasked | {s['turned'] / s['turned_unasked']:.1f}× |" if s["turned_unasked"] else
         "| ratio asked / unasked | – (no turn unasked) |", "",
         *([f"Her turns after a request that went the asked way: {way_share(s, 'left')} of those asked to her left, "
            f"{way_share(s, 'right')} to her right. His own facing over a request: a median "
            f"{s['his_turn']:+.0f} degrees the asked way ({s['his_turn_unasked']:+.0f} over the same moments unasked; "
            f"the recorded leader around her turns: `python -m training.evaluation.recorded_leads`).", ""]
           if s.get("his_turn") is not None else []),
         f"His hand above {HAND_RAISED:g} m within {REQUEST_SECONDS:g} s: {100 * s['hand_raised']:.0f} % of the requests, "
         f"{100 * s['hand_raised_unasked']:.0f} % of the same moments unasked.", "",
         *([f"Her reading of his hand, unasked: she turns in {100 * s['turned_unasked_hand_up']:.0f} % of the moments "
            f"his hand went up and in {100 * s['turned_unasked_hand_down']:.0f} % of the others "
            f"(the recorded follower: `python -m training.evaluation.recorded_leads`, its last line).", ""]
           if s.get("turned_unasked_hand_up") is not None and s.get("turned_unasked_hand_down") is not None else []),
         *([f"Does he lead? A detector of the recorded leads (training.evaluation.turn_cues, leader_body: his "
            f"own body and plan, not where she is; a turn completing {LEGIBILITY_LEAD:g} s later) sees him lead the asked "
            f"way in {100 * s['lead_seen']:.0f} % of the requests and in {100 * s['lead_seen_unasked']:.0f} % "
            f"of the same moments unasked.", ""] if "lead_seen" in s else []),
         f"Median time from the request to the turn's 300 degrees: {s['median_seconds']:.2f} s. "
         f"Seed whose requests worked least often: {s['worst_request_seed']}." if s["median_seconds"] is not None else
         "No request was followed by a turn.", "",
         "## Dancing unasked (figures.py), against the recording of takes " + ", ".join(res["takes"]), "",
         *dancing_table(s, ref)]
    path.write_text("\n".join(L) + "\n")


def run(args) -> dict:
    t0 = time.time()
    manifest, onnx, leader_path = find_models(args.models)
    if leader_path is None or "ours" not in onnx and args.method not in onnx:
        raise EvalError(f"{args.models}: needs leader.onnx and the follower {args.method}")
    error = O.resolve(args, manifest)
    if error:
        raise EvalError(f"{args.models}/manifest.json: {error}")
    leader = O.leader_policy(load_onnx(leader_path), manifest, args)
    follower = O.follower_policy(load_onnx(onnx[args.method]), manifest, args, args.temperature)
    takes = [t for t in args.takes.split(",") if t]
    ref = recording(args.data, takes)
    detector = None
    if args.legibility:
        cues = C.load(args.data)
        detector = C.fit_detector(cues, sorted(cues), "leader_body", int(round(LEGIBILITY_LEAD * FPS)),
                                  argparse.Namespace(classifier="logistic", c=0.01))
    per_seed = []
    for seed in tqdm(range(args.first_seed, args.first_seed + args.seeds), desc="duets", unit="duet",
                     file=sys.stderr, disable=args.quiet):
        per_seed.append(one_duet(manifest, leader, follower, args.temperature, seed, args.seconds, detector, args.tempo,
                                 bool(args.figures)))
    return {"takes": takes, "recording": ref, "per_seed": per_seed, "summary": summary(per_seed, ref),
            "config": {"models": str(args.models), "method": args.method, "seeds": args.seeds,
                       "seconds": args.seconds, "figures": args.figures, "temperature": args.temperature,
                       "follower_temperature": args.follower_temperature, "guard": args.guard,
                       "wall_seconds": time.time() - t0}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m training.evaluation.lead", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    add_folder(ap, "data", "read: the recorded dancers to compare with")
    add_folder(ap, "models", "read: the leader and the follower")
    ap.add_argument("--method", default="ours", help="the follower (ours, ccm, or another follower model's name)")
    ap.add_argument("--takes", default=",".join(TEST_TAKES))
    ap.add_argument("--seeds", type=int, default=100)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--seconds", type=float, default=14.0, help="per duet (a request every 7 s after 3 s)")
    ap.add_argument("--figures", type=int, choices=(0, 1), default=0,
                    help="1: he also leads figures of his own (the page's default); 0: only those asked (?figures=0)")
    ap.add_argument("--no-legibility", dest="legibility", action="store_false",
                    help="skip the lead detector (fitted on every take of --data, about 20 s here)")
    O.add_options(ap)
    ap.add_argument("--out", default="runs/lead")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    if args.seeds < 1 or args.seconds < WARM_UP + REQUEST_SECONDS:
        ap.error(f"--seeds must be at least 1 and --seconds at least {WARM_UP + REQUEST_SECONDS:g}")
    try:
        res = run(args)
    except (EvalError, DataError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "lead.json").write_text(json.dumps(res, indent=1))
    write_markdown(out / "lead.md", res)
    print((out / "lead.md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
