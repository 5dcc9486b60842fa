"""evaluation/options.py: the evaluation commands dance as the page does unless told otherwise."""
import argparse

import numpy as np
import pytest

from training.evaluation import options as O
from training.mirror.guard import UprightGuard, Variety

RANGES = {"hip_low": 0.7, "head_above_hip_low": 0.6, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}
OFFSETS = np.zeros((17, 3)).tolist()


def parse(*argv):
    ap = argparse.ArgumentParser()
    O.add_options(ap)
    return ap.parse_args(list(argv))


def manifest(**extra):
    return {"defaultTemperature": 1.0, "plausibility": RANGES,
            "skeleton": {"offsets": {"follower": OFFSETS, "leader": OFFSETS}}, **extra}


def policy(x, temperature, rng):
    return {"output": np.zeros((len(np.atleast_2d(x)), 323))}


def test_defaults_come_from_the_manifest():
    m = manifest(leaderTemperature=0.5, guard={"samples": 8, "margin": 0.05})
    args = parse()
    assert O.resolve(args, m) is None
    assert (args.temperature, args.follower_temperature, args.guard, args.guard_margin) == (0.5, 1.0, 8, 0.05)
    f = O.follower_policy(policy, m, args, args.temperature)
    assert isinstance(f, UprightGuard) and f.samples == 8 and f.temperature == 1.0 and f.margin == 0.05
    assert f.hip_slack == 0.0                               # no hipMargin: her hips from the one margin
    hips = manifest(leaderTemperature=0.5, guard={"samples": 8, "margin": 0.05, "hipMargin": 0.15})
    args = parse()
    assert O.resolve(args, hips) is None and args.guard_hip_margin == 0.15
    assert O.follower_policy(policy, hips, args, args.temperature).hip_slack == pytest.approx(-0.1)
    args = parse("--guard-hip-margin", "0.05")
    assert O.resolve(args, hips) is None and O.follower_policy(policy, hips, args, 0.5).hip_slack == 0.0
    assert "--guard-hip-margin" in O.resolve(parse("--guard-hip-margin", "-1"), hips)


def test_options_override_the_manifest_and_an_old_manifest_has_no_guard():
    m = manifest(leaderTemperature=0.5, guard={"samples": 8, "margin": 0.05})
    args = parse("--guard", "0", "--follower-temperature", "0.7")
    assert O.resolve(args, m) is None
    f = O.follower_policy(policy, m, args, args.temperature)
    assert isinstance(f, Variety) and f.temperature == 0.7
    old = parse()
    assert O.resolve(old, manifest()) is None   # no leaderTemperature, no guard: both at the default
    assert (old.temperature, old.follower_temperature, old.guard) == (1.0, 1.0, 0)
    assert O.follower_policy(policy, manifest(), old, old.temperature) is policy


def test_the_leader_is_guarded_as_the_manifest_says():
    m = manifest(leaderTemperature=0.5, leaderGuard={"samples": 8, "margin": 0.1})
    args = parse()
    assert O.resolve(args, m) is None and args.leader_guard == 8
    lead = O.leader_policy(policy, m, args)
    # His own variety stays the duet's (the leader's temperature); the margin is the manifest's.
    assert isinstance(lead, UprightGuard) and lead.samples == 8 and lead.temperature is None and lead.margin == 0.1
    assert lead.head_margin is None                       # a manifest without headMargin: the one margin
    head = manifest(leaderTemperature=0.5, leaderGuard={"samples": 8, "margin": 0.07, "headMargin": 0.03})
    assert O.leader_policy(policy, head, args).head_margin == 0.03
    assert lead.hip_margin is None and O.leader_policy(policy, head, args).hip_margin is None
    hips = manifest(leaderTemperature=0.5, leaderGuard={"samples": 8, "margin": 0.07, "hipMargin": 0.1})
    guarded = O.leader_policy(policy, hips, args)
    assert guarded.hip_margin == 0.1 and guarded.hip_slack == pytest.approx(0.07 - 0.1)
    assert not guarded.keep_plan                          # no keepPlan: a request's plan is not kept to
    plan = manifest(leaderTemperature=0.5, leaderGuard={"samples": 8, "margin": 0.07, "keepPlan": True})
    assert O.leader_policy(policy, plan, args).keep_plan == 1   # true: the nearest the plan
    among = manifest(leaderTemperature=0.5, leaderGuard={"samples": 8, "margin": 0.07, "keepPlan": 3})
    assert O.leader_policy(policy, among, args).keep_plan == 3
    off = parse("--leader-guard", "0")
    assert O.resolve(off, m) is None and O.leader_policy(policy, m, off) is policy
    old = parse()
    assert O.resolve(old, manifest()) is None and O.leader_policy(policy, manifest(), old) is policy


@pytest.mark.parametrize("argv,m,words", [
    (("--guard", "1"), manifest(), "at least 2 samples"),
    (("--leader-guard", "1"), manifest(), "at least 2 samples"),
    (("--temperature", "-1"), manifest(), "negative"),
    (("--guard", "8"), {"defaultTemperature": 1.0}, "plausibility range"),
])
def test_bad_options_are_refused_in_plain_words(argv, m, words):
    assert words in O.resolve(parse(*argv), m)


def test_the_shipped_manifest_carries_the_guards_export_writes():
    """The guards' settings in public/models/manifest.json are guard.py's, as export writes them
    (the page and every evaluation command read them from there)."""
    import json
    from pathlib import Path

    from training.mirror import guard as G

    shipped = json.loads((Path(__file__).parents[2] / "public/models/manifest.json").read_text())
    follower = {"samples": G.SAMPLES, "margin": G.MARGIN}
    if G.FOLLOWER_HIP_MARGIN is not None:
        follower["hipMargin"] = G.FOLLOWER_HIP_MARGIN
    leader = {"samples": G.LEADER_SAMPLES, "margin": G.LEADER_MARGIN}
    if G.LEADER_HEAD_MARGIN is not None:
        leader["headMargin"] = G.LEADER_HEAD_MARGIN
    if G.LEADER_HIP_MARGIN is not None:
        leader["hipMargin"] = G.LEADER_HIP_MARGIN
    if G.LEADER_KEEP_PLAN:
        leader["keepPlan"] = G.LEADER_KEEP_PLAN
    assert shipped["guard"] == follower and shipped["leaderGuard"] == leader
