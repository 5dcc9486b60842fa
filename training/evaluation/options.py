"""How the evaluation commands run the two dancers: by default as the page does, from the manifest.

The manifest says each dancer's variety (temperature: `leaderTemperature` for the leader model,
`defaultTemperature` for the follower, the page's "variety" slider) and the follower's upright guard
("guard": samples and margin, training/mirror/guard.py). soak, seeds, interaction and
scripts/worst_seed.py take these options, fill what is not given from the manifest (`resolve`) and
wrap their follower with `follower_policy`. A manifest without those fields (older exports) runs
both dancers at `defaultTemperature` with no guard, as the page then does.

    python -m training.evaluation.seeds --guard 0                       # the follower without its guard
    python -m training.evaluation.soak --temperature 0.5 --follower-temperature 1 --guard 8 --guard-margin 0.05
"""
from __future__ import annotations

import argparse

from ..mirror.guard import UprightGuard, Variety
from ..mirror.on_count import HIPS as ON_COUNT_HIPS, STRENGTH as ON_COUNT_STRENGTH, OnCount
from ..mirror.music import DEFAULT_TEMPO


def add_options(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--tempo", type=float, default=None, metavar="BPM",
                    help="the music's tempo the duet dances to, beats a minute (default: the manifest's music.tempo)")
    ap.add_argument("--temperature", type=float, default=None,
                    help="the leader's variety (default: the manifest's leaderTemperature, else defaultTemperature)")
    ap.add_argument("--leading-temperature", type=float, default=None,
                    help="the leader's variety while he leads a figure the visitor asked for (rollout.leader_variety; default: the manifest's "
                         "leadingTemperature, else his own throughout)")
    ap.add_argument("--follower-temperature", type=float, default=None,
                    help="the follower's variety (default: the manifest's defaultTemperature, the page's slider)")
    ap.add_argument("--guard", type=int, default=None, metavar="K",
                    help="the follower's upright guard with K samples (training/mirror/guard.py; 0: off; "
                         "default: the manifest's)")
    ap.add_argument("--guard-margin", type=float, default=None, metavar="M",
                    help="the guard acts once the drawn pose is within M metres of the range's edge "
                         "(default: the manifest's)")
    ap.add_argument("--guard-hip-margin", type=float, default=None, metavar="M",
                    help="the follower's guard judges her hips from M metres before the range's edge "
                         "(default: the manifest's guard.hipMargin, else the guard's margin)")
    ap.add_argument("--on-count", type=int, default=None, metavar="K",
                    help="both dancers' guards choose, every step, the one of K samples whose footwork follows "
                         "the count (training/mirror/on_count.py; 0: off; default: the manifest's onCount.samples)")
    ap.add_argument("--on-count-strength", type=float, default=None, metavar="S",
                    help="how far the footwork aimed at swings with the beat, 0-1 (default: the manifest's onCount.strength)")
    ap.add_argument("--on-count-hips", type=float, default=None, metavar="W",
                    help="m/s added to the footwork's miss of a candidate whose hips turn back; 0: the hips left alone, "
                         "and a turn's step the network's own (default: the manifest's onCount.hips)")
    ap.add_argument("--on-count-figure", type=float, default=None, metavar="DEG",
                    help="outside a turn, prefer the candidates that turn DEG degrees or more the way of the dancer's own "
                         "turn the figure says runs, none while no figure runs (on_count.FIGURE_TURN); 0: off "
                         "(default: the manifest's onCount.figureTurn)")
    ap.add_argument("--leader-guard", type=int, default=None, metavar="K",
                    help="the leader's upright guard with K samples (0: off; default: the manifest's "
                         "leaderGuard, acting at its margin)")


def resolve(args, manifest: dict) -> str | None:
    """Fill the options not given from the manifest; what is wrong with them, in one line (None: nothing)."""
    guard = manifest.get("guard") or {}
    if getattr(args, "tempo", None) is None:
        args.tempo = float((manifest.get("music") or {}).get("tempo", DEFAULT_TEMPO))
    if not 60 <= args.tempo <= 300:
        return f"--tempo {args.tempo:g}: beats a minute, 60-300 (salsa is danced at 150-210)"
    if args.temperature is None:
        args.temperature = manifest.get("leaderTemperature", manifest["defaultTemperature"])
    if args.follower_temperature is None:
        args.follower_temperature = manifest["defaultTemperature"]
    # Read by rollout.start_duet from the manifest the duets start from: asked for, it is written there.
    if getattr(args, "leading_temperature", None) is None:
        args.leading_temperature = manifest.get("leadingTemperature")
    elif args.leading_temperature < 0:
        return "a temperature (variety) cannot be negative"
    else:
        manifest["leadingTemperature"] = args.leading_temperature
    if args.guard is None:
        args.guard = int(guard.get("samples", 0))
    if args.guard_margin is None:
        args.guard_margin = float(guard.get("margin", 0.0))
    if getattr(args, "guard_hip_margin", None) is None:
        args.guard_hip_margin = guard.get("hipMargin")
    if args.guard_hip_margin is not None and args.guard_hip_margin < 0:
        return f"--guard-hip-margin {args.guard_hip_margin}: metres, 0 or more"
    if getattr(args, "leader_guard", None) is None:
        args.leader_guard = int((manifest.get("leaderGuard") or {}).get("samples", 0))
    if args.leader_guard < 0 or args.leader_guard == 1:
        return f"--leader-guard {args.leader_guard}: 0 (off) or at least 2 samples to choose from"
    if args.guard < 0 or args.guard == 1:
        return f"--guard {args.guard}: 0 (off) or at least 2 samples to choose from"
    if min(args.temperature, args.follower_temperature) < 0:
        return "a temperature (variety) cannot be negative"
    on_count = manifest.get("onCount") or {}
    if getattr(args, "on_count", None) is None:
        args.on_count = int(on_count.get("samples", 0))
    if getattr(args, "on_count_strength", None) is None:
        args.on_count_strength = float(on_count.get("strength", ON_COUNT_STRENGTH))
    if getattr(args, "on_count_hips", None) is None:
        args.on_count_hips = float(on_count.get("hips", ON_COUNT_HIPS))
    if getattr(args, "on_count_figure", None) is None:
        args.on_count_figure = float(on_count.get("figureTurn", 0.0))
    if not args.on_count_figure >= 0:
        return f"--on-count-figure {args.on_count_figure:g}: 0 (off) or more degrees"
    if args.on_count < 0 or args.on_count == 1:
        return f"--on-count {args.on_count}: 0 (off) or at least 2 samples to choose from"
    if not 0 <= args.on_count_strength <= 1:
        return f"--on-count-strength {args.on_count_strength:g}: 0 to 1"
    if not args.on_count_hips >= 0:
        return f"--on-count-hips {args.on_count_hips:g}: 0 (the hips left alone) or more m/s"
    if args.on_count and not (args.guard or args.leader_guard):
        return "--on-count chooses inside the upright guards: it needs --guard or --leader-guard"
    if args.guard and not manifest.get("plausibility"):
        return "the upright guard needs the manifest's plausibility range: re-export the models"
    return None


def follower_policy(policy, manifest: dict, args, leader_temperature: float):
    """The follower's policy as the (resolved) options ask: guarded (judging the body the follower's
    bones draw, her hips from the guard's hipMargin when it has one), at its own variety, or as it is."""
    temperature = None if args.follower_temperature == leader_temperature else args.follower_temperature
    if args.guard:
        hips = getattr(args, "guard_hip_margin", None)
        return UprightGuard(policy, manifest["plausibility"], args.guard, temperature, args.guard_margin,
                            manifest["skeleton"]["offsets"]["follower"], hip_margin=None if hips is None else float(hips),
                            on_count=on_count_for("follower", args))
    return policy if temperature is None else Variety(policy, temperature)


def leader_policy(policy, manifest: dict, args):
    """The leader's policy as the (resolved) options ask: guarded like the follower (at the
    manifest's leaderGuard margin, his head over his hips at its headMargin and his hips at its
    hipMargin when it has them, judging the body his bones draw, his lead hand kept to a request's
    plan when it says keepPlan), or as it is."""
    samples = getattr(args, "leader_guard", 0) or 0
    if samples and manifest.get("plausibility"):
        settings = manifest.get("leaderGuard") or {}
        head, hips = settings.get("headMargin"), settings.get("hipMargin")
        return UprightGuard(policy, manifest["plausibility"], samples, None, float(settings.get("margin", 0.0)),
                            manifest["skeleton"]["offsets"]["leader"], None if head is None else float(head),
                            hip_margin=None if hips is None else float(hips),
                            keep_plan=int(settings.get("keepPlan", 0)), on_count=on_count_for("leader", args))
    return policy


def option_names() -> list[str]:
    """The attribute names of every option add_options adds (what a worker process needs of args to
    build the dancers as the parent does)."""
    ap = argparse.ArgumentParser()
    add_options(ap)
    return [a.dest for a in ap._actions if a.dest != "help"]


def on_count_for(role: str, args) -> OnCount | None:
    """A dancer's chooser on the count as the options ask (None: off)."""
    samples = getattr(args, "on_count", 0) or 0
    if not samples:
        return None
    return OnCount(role, samples, getattr(args, "on_count_strength", ON_COUNT_STRENGTH),
                   getattr(args, "on_count_hips", ON_COUNT_HIPS), figure_turn=getattr(args, "on_count_figure", 0.0) or None)


def restart_count(*policies) -> None:
    """Before a duet, so that it dances as if alone: zero each policy's guard count (a plain policy
    has none), and make its chooser on the count forget the footwork it has seen."""
    for policy in policies:
        if hasattr(policy, "guarded"):
            policy.guarded = 0
        if getattr(policy, "on_count", None) is not None:
            policy.on_count.restart()
