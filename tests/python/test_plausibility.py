"""training.evaluation.plausibility: flags against the recording's range, collapses, worst cases over
seeds; and the decoder that reads the pose beside the code (the cure for stop-motion)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from training.evaluation import plausibility as P
from training.learning.models import CodebookMatching, IntentionPredictor, ModelConfig, StepModel
from training.mirror import features as feat
from training.mirror.skeleton import FPS


def standing(frames: int, sway: float = 0.01, seed: int = 0) -> np.ndarray:
    """[frames, 17, 3]: an upright body (hip at 1 m) that breathes and sways a little."""
    rng = np.random.default_rng(seed)
    base = np.zeros((17, 3))
    base[:, 1] = [1.0, 1.15, 1.3, 1.5, 1.65, 1.45, 1.2, 0.95, 1.45, 1.2, 0.95, 0.95, 0.5, 0.08, 0.95, 0.5, 0.08]
    base[[5, 6, 7, 11, 12, 13], 0] = 0.2        # left side
    base[[8, 9, 10, 14, 15, 16], 0] = -0.2      # right side
    base[[6, 9], 2] = 0.05                      # elbows a little forward: the bends are not degenerate
    base[[12, 15], 2] = 0.03
    t = np.arange(frames)[:, None, None]
    out = base[None] + sway * np.sin(t / 7.0 + np.arange(17)[None, :, None] + np.arange(3))
    return out + rng.normal(0, 0.002, out.shape)


def test_a_recording_like_motion_is_rarely_flagged():
    walk = standing(600)
    r = P.ranges([walk])
    flags = P.frame_flags(standing(600, seed=1), r)
    for k in ["hips_low", "head_low", "feet_wide"]:
        assert flags[k].mean() < 0.1, k
    # 16 angles, each outside its own 0.5..99.5 percentile in about 1 % of such noisy frames
    assert flags["angles_out"].mean() < 0.3
    assert flags["frozen"].mean() == 0


def test_lying_on_the_floor_is_flagged_and_a_long_one_is_a_collapse():
    r = P.ranges([standing(600)])
    lying = standing(2 * FPS)
    lying[..., 1], lying[..., 2] = 0.3 + 0.02 * lying[..., 2], lying[..., 1]   # the body turned onto its back
    motion = np.concatenate([standing(FPS), lying, standing(FPS)])
    flags = P.frame_flags(motion, r)
    lying_frames = slice(FPS, 3 * FPS)
    assert flags["hips_low"][lying_frames].all()
    assert flags["head_low"][lying_frames].all()
    assert flags["angles_out"][lying_frames].all()    # the torso's lean
    assert P.collapsed(motion, r)
    assert abs(P.worst_second(flags) - 1.0) < 1e-9
    first = P.first_bad_second(flags)                 # the first second mostly on the floor
    assert FPS // 2 <= first <= FPS and P.second_shares(flags)[first] > P.BAD_SECOND
    assert P.first_bad_second(P.frame_flags(standing(3 * FPS), r)) is None
    short = np.concatenate([standing(FPS), lying[:FPS // 2], standing(FPS)])
    assert not P.collapsed(short, r)


def test_a_held_body_shape_is_frozen_even_while_the_root_moves():
    still = np.repeat(standing(1), 40, 0)
    still[:, :, 0] += np.linspace(0, 1, 40)[:, None]   # carried along, turning nothing: still one shape
    flags = P.frame_flags(still, P.ranges([standing(600)]))
    assert flags["frozen"][1:].all() and not flags["frozen"][0]
    assert P.longest_run(flags["frozen"]) == 39


def test_summary_reports_the_worst_seed_not_only_the_mean():
    r = P.ranges([standing(600)])
    good = P.duet(standing(300), standing(300, seed=2), r)
    lying = standing(300)
    lying[..., 1] = 0.3
    bad = P.duet(standing(300), lying, r)
    s = P.summarize([good] * 9 + [bad], [300] * 10)
    assert 0.1 <= s["follower"]["hips_low"] < 0.15        # one seed in ten lies, the rest barely
    assert s["follower"]["hips_low_worst_seed"] == 1.0
    assert s["follower"]["hips_low_worst_seed"] == 1.0
    assert s["follower"]["collapses"] == 1 and s["follower"]["bad_seconds"] == 1
    assert s["leader"]["collapses"] == 0


def test_path_ratio_follows_travel_not_sway():
    lead = standing(300)
    lead[:, :, 0] += np.linspace(0, 3, 300)[:, None]     # 3 m of travel
    follow = standing(300)
    follow[:, :, 0] += 0.1 * np.sin(np.arange(300) * 2 * np.pi / 15)[:, None]   # stepping on the spot, 2 Hz
    d = P.duet(lead, follow, P.ranges([standing(600)]))
    assert d["path_ratio"] < 0.2


def test_a_decoder_that_reads_the_pose_moves_on_under_one_code():
    """With the same code, the decoder from the code alone gives the same pose whatever the
    dancer's state (stop-motion); reading the pose, it gives another pose for another state. The
    step model's gather decoding equals the module's one-hot decoding in both."""
    torch.manual_seed(0)
    for state in (False, True):
        cfg = ModelConfig(hidden=32, intention_hidden=16, channels=3, classes=4, decoder_state=state)
        matching, predictor = CodebookMatching(cfg).eval(), IntentionPredictor(cfg).eval()
        stats = {f"{k}_{s}": (torch.zeros(n) if s == "mean" else torch.ones(n))
                 for k, n in (("input", feat.INPUT_SIZE), ("output", feat.OUTPUT_SIZE),
                              ("intention", feat.INTENTION_SIZE)) for s in ("mean", "std")}
        step = StepModel(cfg, predictor, matching, stats).eval()
        x = torch.randn(2, feat.INPUT_SIZE)
        code = torch.tensor([[1, 2, 3], [1, 2, 3]])
        one_hot = torch.nn.functional.one_hot(code, 4).float().reshape(2, -1)
        with torch.no_grad():
            y = step.decode(code, x)
            assert torch.allclose(y, matching.decode(one_hot, x), atol=1e-5)
        assert torch.allclose(y[0], y[1]) != state
        assert len(cfg.state_columns) == (17 * 6 if state else 0)


def test_state_columns_are_the_own_pose_positions_and_velocities():
    for role, layout in (("follower", feat.FOLLOWER_INPUT_LAYOUT), ("leader", feat.LEADER_INPUT_LAYOUT)):
        cols = ModelConfig(role=role, decoder_state=True).state_columns
        pose = feat.block_slices(layout)["self_pose"]
        assert min(cols) == pose.start and max(cols) < pose.stop
        assert cols[:7] == [pose.start + i for i in range(6)] + [pose.start + 12]
        assert replace(ModelConfig(role=role), decoder_state=False).state_columns == []


def test_a_decoder_that_hears_the_music_reads_the_count_and_never_has_it_hidden():
    """decoder_music: the music block follows the pose among the decoder's columns; a step decoded
    from one code changes with the count, and hiding the state (state_keep 0) hides the pose only."""
    torch.manual_seed(0)
    cfg = ModelConfig(hidden=32, intention_hidden=16, channels=3, classes=4, decoder_state=True, decoder_music=True)
    music = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)["music"]
    assert cfg.music_columns == list(range(music.start, music.stop))
    assert cfg.state_columns[-len(cfg.music_columns):] == cfg.music_columns
    assert len(cfg.state_columns) == 17 * 6 + music.stop - music.start
    matching = CodebookMatching(cfg).eval()
    code = torch.nn.functional.one_hot(torch.tensor([[1, 2, 3]]), 4).float().reshape(1, -1).repeat(2, 1)
    x = torch.randn(1, feat.INPUT_SIZE).repeat(2, 1)
    x[1, music] += 1.0   # another count, the same pose
    with torch.no_grad():
        assert not torch.allclose(*matching.decode(code, x))
        hidden = matching.decode(code, x, state_keep=torch.zeros(2, 1))
        other_pose = x.clone()
        other_pose[:, cfg.state_columns[0]] += 5.0
        assert torch.allclose(hidden, matching.decode(code, other_pose, state_keep=torch.zeros(2, 1)))
        assert not torch.allclose(*hidden)   # the count still tells the two apart


def test_seeds_judges_every_seed_of_the_exported_models_against_the_recording(exported, data3, tmp_path):
    """training.evaluation.seeds end to end on the smoke models: one row per seed, shares and
    their ratios to the recording, alone and with the layer."""
    import json

    from conftest import SMALL_TAKES
    from training.evaluation import seeds

    out = tmp_path / "seeds"
    rc = seeds.main(["--data", str(data3), "--models", str(exported["models"]), "--takes", SMALL_TAKES["test"],
                     "--methods", "ours", "--seeds", "2", "--seconds", "3", "--workers", "1",
                     "--out", str(out), "--quiet"])
    assert rc == 0
    res = json.loads((out / "seeds.json").read_text())
    row = res["methods"]["ours"]
    assert [s["seed"] for s in row["per_seed"]] == [0, 1]
    for kind in ("alone", "layer"):
        for who in ("leader", "follower"):
            assert set(P.FLAGS) <= set(row[kind][who]) and row[kind]["seeds"] == 2
            assert 0 <= row[kind][who]["frozen_worst_seed"] <= 1
        assert set(seeds.INTERACTION) <= set(row["ratio"][kind])
    assert "| recording |" in (out / "seeds.md").read_text()


def test_seeds_refuses_a_manifest_without_the_range(exported, data3, tmp_path, capsys):
    import json
    import shutil

    from training.evaluation import seeds

    models = tmp_path / "models"
    shutil.copytree(exported["models"], models)
    manifest = json.loads((models / "manifest.json").read_text())
    del manifest["plausibility"]
    (models / "manifest.json").write_text(json.dumps(manifest))
    assert seeds.main(["--data", str(data3), "--models", str(models), "--out", str(tmp_path / "o")]) == 2
    assert "no plausibility range" in capsys.readouterr().err


def test_the_upright_guard_takes_the_most_upright_of_the_networks_own_samples():
    """mirror/guard.py (the page's upright guard): an upright first sample passes untouched; a low one
    is replaced by the most upright of K fresh samples, and the step is counted."""
    from training.mirror.guard import POSE, UprightGuard, upright_margin
    from training.evaluation.plausibility import CHEST
    from training.mirror.skeleton import HEAD

    lean = 0.6                            # the steepest torso the range allows (radians)
    r = {"hip_low": 0.7, "head_above_hip_low": 0.6, "feet_wide": 1.0, "angle_high": [3.0, lean]}

    def output(hip: float, chest_sideways: float = 0.0) -> np.ndarray:
        out = np.zeros(feat.OUTPUT_SIZE, np.float32)
        pose = out[POSE].reshape(feat.N_JOINTS, 12)
        pose[:, 1] = hip                  # every joint at the hip's height, feet together ...
        pose[HEAD, 1] = hip + 0.7         # ... the head 0.7 m above
        pose[CHEST, :2] = chest_sideways, hip + 0.4 - chest_sideways   # the chest above the hips
        out[POSE] = pose.reshape(-1)
        return out

    hips = iter([1.0, 0.5, 0.4, 0.9, 0.6])   # the first call: one sample; the second: the guard's batch
    calls = []

    def policy(x, temperature, rng):
        calls.append((len(np.atleast_2d(x)), temperature))
        outs = np.stack([output(next(hips)) for _ in range(len(np.atleast_2d(x)))])
        return {"output": outs, "code": np.arange(len(outs))[:, None]}

    assert np.allclose(upright_margin(np.stack([output(1.0), output(0.5)]), r), [0.1, -0.2])
    # Hips and head high, the torso tipped: the chest 0.3 m out over 0.1 m up leans past 0.6 rad.
    tipped = np.hypot(0.3, 0.1) * np.sin(lean) - 0.3
    assert tipped < 0 and np.allclose(upright_margin(output(1.0, 0.3), r), [tipped], atol=1e-6)
    # With bone offsets the guard judges the body the rollout draws: the decoded rotations through
    # the bones. Upright rotations stand; the same joint positions with every joint turned 90°
    # about x (up becomes forward) draw a body lying flat, and the guard sees it.
    offsets = np.zeros((feat.N_JOINTS, 3))
    offsets[1:, 1] = 0.2                  # every bone 20 cm long, pointing up: a straight column
    standing, lying = output(1.0), output(1.0)
    for out, (fwd, up) in ((standing, ((0, 0, 1), (0, 1, 0))), (lying, ((0, -1, 0), (0, 0, 1)))):
        pose = out[POSE].reshape(feat.N_JOINTS, 12)
        pose[:, 6:9], pose[:, 9:12] = fwd, up
        out[POSE] = pose.reshape(-1)
    assert upright_margin(standing, r, offsets)[0] > 0
    assert upright_margin(lying, r, offsets)[0] < -0.5 and upright_margin(lying, r)[0] > 0
    guard = UprightGuard(policy, r, samples=3, temperature=1.0)
    x = np.zeros(feat.INPUT_SIZE, np.float32)
    rng = np.random.default_rng(0)
    assert guard(x, 0.5, rng)["output"][0][POSE][1] == 1.0 and guard.guarded == 0
    chosen = guard(x, 0.5, rng)          # 0.5 is low: the batch offers 0.4, 0.9, 0.6
    assert chosen["output"][0][POSE][1] == np.float32(0.9) and chosen["code"][0, 0] == 1
    assert guard.guarded == 1 and calls == [(1, 1.0), (1, 1.0), (3, 1.0)]


def test_seeds_runs_the_guard_and_refuses_a_guard_of_one(exported, data3, tmp_path, capsys):
    import json

    from conftest import SMALL_TAKES
    from training.evaluation import seeds

    base = ["--data", str(data3), "--models", str(exported["models"]), "--takes", SMALL_TAKES["test"],
            "--methods", "ours", "--seeds", "1", "--seconds", "2", "--workers", "1", "--quiet"]
    assert seeds.main(base + ["--guard", "4", "--follower-temperature", "1", "--out", str(tmp_path / "g")]) == 0
    res = json.loads((tmp_path / "g" / "seeds.json").read_text())
    assert res["config"]["guard"] == 4 and res["config"]["follower_temperature"] == 1.0
    row = res["methods"]["ours"]
    assert row["guarded"] == row["per_seed"][0]["guarded"] >= 0
    assert "upright guard (training/mirror/guard.py): 4 samples" in (tmp_path / "g" / "seeds.md").read_text()
    assert seeds.main(base + ["--guard", "1", "--out", str(tmp_path / "o")]) == 2
    assert "--guard 1" in capsys.readouterr().err


def test_the_leaders_guard_judges_his_head_from_its_own_margin_except_while_he_leads():
    """guard.slack_for and UprightGuard(head_margin=...): the leader's head over his hips is judged
    from the smaller head margin (a narrow range: at the full margin the guard kept his stiffest
    sample), but while his input shows a hands plan (a request runs) from the full one."""
    from training.evaluation.plausibility import CHEST
    from training.mirror.guard import HANDS_PLAN_SHOWN, POSE, UprightGuard, slack_for, upright_margin
    from training.mirror.skeleton import HEAD

    r = {"hip_low": 0.7, "head_above_hip_low": 0.6, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}

    def output(head_over_hip: float) -> np.ndarray:
        out = np.zeros(feat.OUTPUT_SIZE, np.float32)
        pose = out[POSE].reshape(feat.N_JOINTS, 12)
        pose[:, 1] = 1.0                          # hips 0.3 m above their low: only the head can bind
        pose[CHEST, 1] = 1.4                      # the chest straight above the hips
        pose[HEAD, 1] = 1.0 + head_over_hip
        out[POSE] = pose.reshape(-1)
        return out

    bent = output(0.64)                           # 0.04 m above the head's low end
    assert np.allclose(upright_margin(bent, r), [0.04], atol=1e-6)
    assert np.allclose(upright_margin(bent, r, head_slack=0.05), [0.09], atol=1e-6)
    # The hips' part is not let off: a body whose hips are low stays low whatever the slack.
    low = output(0.7)
    low[POSE.start + 1] = 0.72
    assert upright_margin(low, r, head_slack=1.0)[0] < 0.05

    unasked = np.zeros(feat.LEADER_INPUT_SIZE, np.float32)
    leading = unasked.copy()
    leading[HANDS_PLAN_SHOWN] = 1.0
    assert slack_for(unasked, 0.07, 0.03) == pytest.approx(0.04)
    assert slack_for(leading, 0.07, 0.03) == 0.0
    assert slack_for(unasked, 0.07, None) == 0.0
    assert slack_for(np.zeros(feat.INPUT_SIZE), 0.07, 0.03) == pytest.approx(0.04)   # not a leader's input

    calls = []

    def policy(x, temperature, rng):
        calls.append(len(np.atleast_2d(x)))
        outs = np.stack([bent if len(calls) == 1 or len(calls) == 2 else output(0.7)] * len(np.atleast_2d(x)))
        return {"output": outs}

    guard = UprightGuard(policy, r, samples=4, margin=0.07, head_margin=0.03)
    rng = np.random.default_rng(0)
    guard(unasked, 0.5, rng)                      # 0.04 above the low end, the head margin 0.03: passes
    assert guard.guarded == 0 and calls == [1]
    chosen = guard(leading, 0.5, rng)             # leading: judged from 0.07, so the batch is drawn
    assert guard.guarded == 1 and calls == [1, 1, 4]
    assert chosen["output"][0][POSE][HEAD * 12 + 1] == pytest.approx(1.7)


def test_the_followers_guard_judges_her_hips_from_their_own_margin():
    """UprightGuard(hip_margin=...): her hips are judged from the larger hip margin, the rest of the
    body from the guard's margin, and the batch's pick follows the same judgement."""
    from training.evaluation.plausibility import CHEST
    from training.mirror.guard import POSE, UprightGuard, most_upright, upright_margin
    from training.mirror.skeleton import HEAD

    r = {"hip_low": 0.7, "head_above_hip_low": 0.3, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}

    def output(hips: float) -> np.ndarray:
        out = np.zeros(feat.OUTPUT_SIZE, np.float32)
        pose = out[POSE].reshape(feat.N_JOINTS, 12)
        pose[:, 1] = hips                         # the feet together at the hips' place: only the hips can bind
        pose[CHEST, 1] = hips + 0.4
        pose[HEAD, 1] = hips + 0.7
        out[POSE] = pose.reshape(-1)
        return out

    sinking = output(0.80)                        # 0.10 m above the hips' low end
    assert np.allclose(upright_margin(sinking, r), [0.10], atol=1e-6)
    assert np.allclose(upright_margin(sinking, r, hip_slack=-0.1), [0.0], atol=1e-6)
    assert most_upright(np.stack([sinking, output(0.9), output(0.85)]), r, hip_slack=-0.1) == 1

    calls = []

    def policy(x, temperature, rng):
        calls.append(len(np.atleast_2d(x)))
        return {"output": np.stack([sinking] + [output(0.78 + 0.04 * i) for i in range(1, len(np.atleast_2d(x)))])}

    rng = np.random.default_rng(0)
    plain = UprightGuard(policy, r, samples=4, margin=0.05)
    assert plain(np.zeros(feat.INPUT_SIZE), 0.5, rng)["output"][0][POSE.start + 1] == pytest.approx(0.80)
    assert plain.guarded == 0 and calls == [1]    # 0.10 m up: outside the 0.05 m margin
    hips = UprightGuard(policy, r, samples=4, margin=0.05, hip_margin=0.15)
    chosen = hips(np.zeros(feat.INPUT_SIZE), 0.5, rng)
    assert hips.guarded == 1 and calls == [1, 1, 4]   # within 0.15 m: the batch, and its highest hips
    assert chosen["output"][0][POSE.start + 1] == pytest.approx(0.90)


def test_the_leaders_guard_keeps_his_lead_hand_to_a_requests_plan():
    """guard.lead_hand_miss, nearest_plan, near_plan and UprightGuard(keep_plan=n): while his input
    shows a hands plan, every step draws the batch and takes the standing sample whose lead hand (the
    one the plan puts higher) is nearest the plan's height one step on, or with a chooser on the count
    the one on the count among the n nearest; with no plan, one sample as before."""
    from training.mirror.guard import (HAND_HEIGHTS, HAND_PLAN_FIRST, HANDS_PLAN_SHOWN, POSE, UprightGuard,
                                       drawn_joints, drawn_margin, lead_hand_miss, near_plan, nearest_plan)
    from training.mirror.on_count import OnCount
    from training.mirror.skeleton import HANDS

    # A straight column of 20 cm bones, upright: every joint's drawn height is the hips' plus its depth.
    offsets = np.zeros((feat.N_JOINTS, 3))
    offsets[1:, 1] = 0.2
    r = {"hip_low": 0.7, "head_above_hip_low": 0.0, "feet_wide": 1.0, "angle_high": [3.0, 0.6]}

    def output(hips: float) -> np.ndarray:
        out = np.zeros(feat.OUTPUT_SIZE, np.float32)
        pose = out[POSE].reshape(feat.N_JOINTS, 12)
        pose[0, 1] = hips
        pose[:, 6:9], pose[:, 9:12] = (0, 0, 1), (0, 1, 0)
        out[POSE] = pose.reshape(-1)
        return out

    above_hips = drawn_joints(output(1.0), offsets)[0, HANDS, 1] - 1.0   # each hand's height over the hips
    x = np.zeros(feat.LEADER_INPUT_SIZE)
    x[HANDS_PLAN_SHOWN] = 1.0
    x[HAND_HEIGHTS] = 1.9, 1.8             # his hands now: the left at 1.9 m, the right at 1.8 m
    x[HAND_PLAN_FIRST] = 0.0, 0.5          # the plan raises his right hand 0.5 m by the first key
    target = 1.8 + 0.5 / feat.KEY_STEP     # the right hand leads (2.3 m at the key): 1.9 m one step on
    hips = np.array([1.3, 0.75, target - above_hips[1], 0.6])
    samples = [output(h) for h in hips]
    miss = lead_hand_miss(np.stack(samples), x, offsets)
    assert np.allclose(miss, np.abs(hips + above_hips[1] - target), atol=1e-5) and miss[2] == pytest.approx(0.0, abs=1e-5)
    assert nearest_plan(np.stack(samples), x, r, offsets, margin=0.07) == 2   # 0.75 m is within the margin
    # The nearest must stand: with the range's hips raised past it, the next nearest that stands.
    high = {**r, "hip_low": hips[2] - 0.05}
    assert nearest_plan(np.stack(samples), x, high, offsets, margin=0.07) == 0
    assert nearest_plan(np.stack([output(0.5), output(0.6)]), x, r, offsets, margin=0.07) == 1   # none stands

    calls = []

    def policy(x, temperature, rng):
        calls.append(len(np.atleast_2d(x)))
        return {"output": np.stack(samples[:len(np.atleast_2d(x))])}

    rng = np.random.default_rng(0)
    guard = UprightGuard(policy, r, samples=4, margin=0.07, offsets=offsets, keep_plan=True)
    chosen = guard(x, 0.7, rng)
    assert calls == [4] and guard.kept == 1 and guard.guarded == 0
    assert chosen["output"][0][POSE.start + 1] == pytest.approx(hips[2])
    plain = x.copy()
    plain[HANDS_PLAN_SHOWN] = 0.0          # nobody asks: one sample, as before
    assert guard(plain, 0.7, rng)["output"][0][POSE.start + 1] == pytest.approx(1.3) and calls == [4, 1]
    assert UprightGuard(policy, r, samples=4, offsets=offsets)(x, 0.7, rng) is not None and calls[-1] == 1
    with pytest.raises(ValueError, match="bones"):
        UprightGuard(policy, r, samples=4, keep_plan=True)

    # keep_plan=n with a chooser on the count: among the n standing samples whose hand is nearest
    # the plan (near_plan), the one on the count. A fifth sample stands with its hips (and hand) 10 cm
    # under the nearest one's: its drawn feet move less, which the count asks for here (the music
    # block is zeros: the downbeat, footwork 0).
    samples.append(output(hips[2] - 0.1))
    joints = drawn_joints(np.stack(samples), offsets)
    standing = drawn_margin(joints, r)
    assert near_plan(joints, x, standing, 0.07, 1).tolist() == [False, False, True, False, False]
    assert near_plan(joints, x, standing, 0.07, 2).tolist() == [False, False, True, False, True]
    assert near_plan(joints, x, standing, 0.07, 5).tolist() == [True, False, True, False, True]   # 3 stand
    for n, hip in ((1, hips[2]), (2, hips[2] - 0.1)):
        calls.clear()
        both = UprightGuard(policy, r, samples=5, margin=0.07, offsets=offsets, keep_plan=n, on_count=OnCount("leader", 5))
        assert both(x, 0.7, rng)["output"][0][POSE.start + 1] == pytest.approx(hip) and calls == [5]
