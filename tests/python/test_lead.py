"""Leading a turn: the figure block both dancers read (features.figure_block), the figures of a
duet (rollout.ask_turn, plan_figures) and his hands plan and path for them, the training's hidden
hands plan and turn onsets, and the evaluation tool training.evaluation.lead."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from training.evaluation import lead
from training.learning import train as T
from training.mirror import features as feat
from training.mirror import rollout as ro
from training.mirror.features import FUTURE_OFFSETS, KEYS, Track
from training.mirror.skeleton import FPS, HANDS


def test_the_figure_block_reads_each_figure_over_the_past_and_next_second():
    assert np.all(feat.figure_block(None, np.arange(3)) == 0)
    # Her turn to her left from frame 100 to 140, his turn to his right from 150 to 170.
    kinds = feat.FIGURE_KINDS
    her, his = kinds.index(("her_turn", 1)), kinds.index(("his_turn", -1))
    figures = np.array([(her, 100, 140), (his, 150, 170)])
    block = feat.figure_block(figures, np.array([90, 120, 160])).reshape(3, len(feat.FIGURE_OFFSETS), len(kinds), 2)
    t = np.array([90, 120, 160])[:, None] + feat.FIGURE_OFFSETS[None]
    left = (t >= 100) & (t <= 140)
    right = (t >= 150) & (t <= 170)
    assert np.array_equal(block[..., her, 0], left) and np.array_equal(block[..., his, 0], right)
    assert np.allclose(block[..., her, 1], np.where(left, (t - 100) / 40, 0))
    assert np.allclose(block[..., his, 1], np.where(right, (t - 150) / 20, 0))
    assert block.sum() == block[..., [her, his], :].sum()      # the other kinds stay 0
    # His control stands where her partner's planned path stands; the hands plan is his alone.
    assert feat.LEADER_INPUT_SIZE == feat.INPUT_SIZE + feat.HANDS_PLAN_SIZE


def manifest_duet(leading_temperature: float | None = None, **kw):
    offsets = np.zeros((17, 3)).tolist()
    manifest = {"skeleton": {"offsets": {"leader": offsets, "follower": offsets}}, "startPose": START_POSE}
    if leading_temperature is not None:
        manifest["leadingTemperature"] = leading_temperature
    return ro.start_duet(manifest, **kw)


def run_steps(duet, n):
    """Move the duet's clock n steps on (the figures' own timing only; nobody dances)."""
    for _ in range(n):
        ro.plan_figures(duet)
        duet.frame += 1
        duet.beat += ro.music.beats_per_step(duet.tempo)


def test_a_figure_asked_for_starts_on_the_next_beat_and_both_dancers_read_it():
    duet = manifest_duet(figures=False)
    run_steps(duet, 40)
    ro.ask_turn(duet, 1)
    (led,) = duet.figures.led
    per = ro.music.beats_per_step(duet.tempo)
    start_beat = duet.beat + (led.start - duet.frame) * per
    assert led.way == 1 and led.asked and 0 <= led.start - duet.frame <= 1 / per + 1
    assert start_beat == pytest.approx(round(start_beat), abs=per)        # on a beat of the count
    assert led.name == "her_turn" and (led.end - led.start) * per == pytest.approx(ro.FIGURE_BEATS["her_turn"], abs=per)
    x_leader, x_follower = ro.step_inputs(duet)
    fl = x_leader[feat.block_slices(feat.LEADER_INPUT_LAYOUT)["figure"]]
    ff = x_follower[feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)["figure"]]
    her_left = feat.FIGURE_KINDS.index(("her_turn", 1))
    assert np.array_equal(fl, ff) and fl.reshape(-1, len(feat.FIGURE_KINDS), 2)[-1, her_left, 0] == 1   # coming within the second
    # Asked again before it begins, the new way takes its place.
    ro.ask_turn(duet, -1)
    assert [(f.way, f.asked) for f in duet.figures.led] == [(-1, True)]
    # A request while one runs waits for it to end; a later one takes the waiting one's place.
    run_steps(duet, duet.figures.led[0].start - duet.frame + 2)
    ro.ask_turn(duet, 1)
    ro.ask_turn(duet, -1)
    first, second = duet.figures.led
    assert (first.way, second.way, second.asked) == (-1, -1, True) and second.start > first.end


def test_nobody_asking_he_leads_his_own_figures_at_the_recorded_rate():
    duet = manifest_duet(figures=True, seed=5)
    seen = {}
    for _ in range(30 * 600):     # ten minutes
        run_steps(duet, 1)
        for f in duet.figures.led:
            seen[f.start] = f
    her = [f for f in seen.values() if f.name == "her_turn"]
    his = [f for f in seen.values() if f.name == "his_turn"]
    # The recorded couples, at 163-187 beats a minute: 16.9 of her turns a minute and 6.3 of his.
    assert 13 < len(her) / 10 < 21 and 3.5 < len(his) / 10 < 9
    assert 0.35 < np.mean([f.way > 0 for f in seen.values()]) < 0.65
    assert not any(f.asked for f in seen.values())
    assert not manifest_duet(figures=False).figures.own


START_POSE = {r: {"hip": [0.0, 0.9, 0.0], "forward": [[0.0, 0.0, 1.0]] * 17, "up": [[0.0, 1.0, 0.0]] * 17}
              for r in ("leader", "follower")}


def test_hands_moves_are_where_his_hands_go_less_where_they_are():
    frames = 120
    t = np.arange(frames) / FPS
    positions = np.zeros((frames, 17, 3))
    positions[:, :, 1] = 1.0
    positions[:, HANDS[0], 1] = 1.0 + 0.5 * t            # his left hand rises 0.5 m a second
    heading = np.full(frames, np.pi / 2)                  # facing +x: world +x is his +z (ahead)
    root = np.stack([0.3 * t, np.zeros(frames)], -1)      # walking ahead at 0.3 m/s
    positions[:, :, 0] += root[:, :1]
    me = Track(positions, np.zeros((frames, 17, 3, 3)), root, heading)
    moves = feat.hands_moves(me, np.array([40]))[0]       # [KEYS, 2, 3]
    ahead = FUTURE_OFFSETS / FPS
    assert np.allclose(moves[:, 0, 1], 0.5 * ahead) and np.allclose(moves[:, 1, 1], 0.0)
    assert np.allclose(moves[:, :, 2], 0.3 * ahead[:, None]) and np.allclose(moves[:, :, 0], 0.0, atol=1e-12)
    block = feat.hands_plan_block(moves[None], 1)[0]
    assert block[0] == 1 and np.allclose(block[1:], moves.ravel())
    assert np.all(feat.hands_plan_block(None, 2) == 0)


def test_he_draws_at_the_leading_variety_from_lead_in_before_an_asked_figure_to_its_end():
    duet = manifest_duet(figures=False)
    assert ro.leader_variety(duet, 0.6) == 0.6             # no figure: his own variety
    ro.ask_turn(duet, 1)
    led = duet.figures.led[0]
    seen = []
    for f in (led.start - ro.LEAD_IN - 1, led.start - ro.LEAD_IN, led.start, led.end, led.end + 1):
        duet.frame = f
        duet.leading_temperature = None
        alone = ro.leader_variety(duet, 0.6)
        duet.leading_temperature = 0.9
        seen.append((ro.leading(duet), alone, ro.leader_variety(duet, 0.6)))
    assert seen == [(False, 0.6, 0.6), (True, 0.6, 0.9), (True, 0.6, 0.9), (True, 0.6, 0.9), (False, 0.6, 0.6)]
    led.asked = False                                      # his own figure: his own variety
    duet.frame = led.start
    assert not ro.leading(duet) and ro.leader_variety(duet, 0.6) == 0.6
    assert manifest_duet(0.8).leading_temperature == 0.8 and manifest_duet().leading_temperature is None


def test_his_own_figures_keep_his_own_variety():
    """Nobody asking, every step is drawn at his own variety: a duet without a request (the soak,
    the seeds, rhythm) dances as it did before the leading variety."""
    duet = manifest_duet(0.9, figures=True)
    own = 0
    for _ in range(30 * FPS):
        own += any(f.start <= duet.frame <= f.end for f in duet.figures.led)
        assert ro.leader_variety(duet, 0.6) == 0.6
        run_steps(duet, 1)
    assert own > 10 * FPS                                   # his own figures ran through a third of it


def test_a_figure_raises_his_lead_hand_and_lowers_it():
    duet = manifest_duet(figures=False)
    ro.ask_turn(duet, -1)                                  # her turn to the right: his right hand leads
    led, leader = duet.figures.led[0], duet.leader
    hands = feat.to_root_space_points(leader.positions[HANDS], leader.root, leader.heading)
    assert ro.raised(led, led.start) == 0 and ro.raised(led, led.start + ro.RAISE[0] * FPS) == 1
    assert ro.raised(led, led.end + ro.RAISE[1] * FPS) == 0
    top = np.array(ro.LEAD_HAND_RAISED) * [-1, 1, 1]
    tops = []
    for f in range(led.end + int(ro.RAISE[1] * FPS) + 2):
        duet.frame = f
        moves = ro.hands_input(duet)
        if moves is None:
            tops.append(None)
            continue
        assert np.allclose(moves[:, 0], 0.0)               # the other hand stays where it was
        tops.append(hands[1] + moves[0, 1])               # where the lead hand is to be 1/6 s ahead
    assert np.allclose(led.hands, hands)
    up = tops[led.start + int(ro.RAISE[0] * FPS):led.end - 5]
    assert up and all(np.allclose(t, top) for t in up)  # held up while she turns
    assert tops[-1] is None                                # and no plan once it is down
    duet.frame = led.start
    x_leader, _ = ro.step_inputs(duet)
    assert x_leader[feat.block_slices(feat.LEADER_INPUT_LAYOUT)["hands_plan"]][0] == 1


def test_his_planned_path_leads_her_turns_way():
    duet = manifest_duet(figures=False)
    ro.ask_turn(duet, 1)
    led = duet.figures.led[0]
    duet.frame = led.start
    before = duet.leader.track.heading.copy()
    ro.lead_plan(duet)
    turned = np.degrees(duet.leader.track.heading - before)[ro.NOW + FUTURE_OFFSETS]
    share = np.array([ro.figure_share(led, led.start + o) for o in FUTURE_OFFSETS])
    assert np.allclose(turned, ro.LEAD_TURN * share) and turned[-1] > 0


def test_training_hides_the_hands_plan_in_a_share_of_samples():
    block = "hands_plan"
    x = torch.ones(4000, feat.LEADER_INPUT_SIZE)
    hidden = T.hide_block(x, block, 0.5, torch.Generator().manual_seed(0))
    sl = feat.block_slices(feat.LEADER_INPUT_LAYOUT)[block]
    share = (hidden[:, sl] == 0).all(1).float().mean().item()
    assert 0.45 < share < 0.55
    assert torch.equal(hidden[:, :sl.start], x[:, :sl.start]) and torch.equal(hidden[:, sl.stop:], x[:, sl.stop:])


def test_turn_onsets_need_a_turn_ahead_and_none_behind():
    si, so = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT), feat.block_slices(feat.OUTPUT_LAYOUT)

    def sample(past_deg, future_deg):
        x, y = np.zeros(feat.INPUT_SIZE), np.zeros(feat.OUTPUT_SIZE)
        # Headings of the keys, turning evenly: past keys end at 0 now, future keys start from 0.
        past = np.radians(past_deg) * (np.arange(-KEYS, 0) / KEYS)
        fut = np.radians(future_deg) * (np.arange(1, KEYS + 1) / KEYS)
        x[si["self_trajectory_past"]] = np.stack([0 * past, 0 * past, np.sin(past), np.cos(past)], -1).ravel()
        y[so["trajectory_future"]] = np.stack([0 * fut, 0 * fut, np.sin(fut), np.cos(fut)], -1).ravel()
        return x, y

    cases = [(0, 300, True), (0, -200, True), (0, 120, False), (200, 300, False)]
    x, y = map(np.stack, zip(*[sample(p, f) for p, f, _ in cases]))
    assert T.turn_onsets(x, y).tolist() == [c[2] for c in cases]


def test_only_the_turns_his_raised_hand_leads_weigh_more_with_unled_turn_weight():
    """onset_weights: a turn onset whose leader's higher hand goes above HAND_RAISED in her intention
    target weighs turn_weight; one he does not lead weighs unled_turn_weight (turn_weight without it)."""
    si, so = feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT), feat.block_slices(feat.OUTPUT_LAYOUT)
    fut = np.radians(300) * (np.arange(1, KEYS + 1) / KEYS)
    x, y = np.zeros((3, feat.INPUT_SIZE)), np.zeros((3, feat.OUTPUT_SIZE))
    x[:, si["self_trajectory_past"]] = np.tile([0, 0, 0, 1], KEYS)          # facing ahead, no turn behind
    y[:2, so["trajectory_future"]] = np.stack([0 * fut, 0 * fut, np.sin(fut), np.cos(fut)], -1).ravel()
    y[2, so["trajectory_future"]] = np.tile([0, 0, 0, 1], KEYS)             # no turn ahead
    j = np.zeros((3, feat.INTENTION_SIZE)).reshape(3, KEYS, feat.N_KEY_JOINTS, 3)
    j[:, :, :, 1] = 1.0                                                      # every key joint at 1 m
    j[0, 3, 2, 1] = T.HAND_RAISED + 0.1                                         # his right hand up at one key
    j[2] = j[0]
    j = j.reshape(3, -1)
    assert T.led_onsets(j).tolist() == [True, False, True]
    weights = lambda **kw: T.onset_weights(T.TrainConfig(**kw), x, y, j, "follower").tolist()
    assert weights(turn_weight=8.0, unled_turn_weight=1.0) == [8.0, 1.0, 1.0]
    assert weights(turn_weight=4.0) == [4.0, 4.0, 1.0]


def test_the_leaders_own_turn_starts_weigh_own_turn_weight():
    """own_onset_weights: read from his own path (not the figure block, not hers); 1 everywhere
    for the follower and without the setting."""
    si, so = feat.block_slices(feat.LEADER_INPUT_LAYOUT), feat.block_slices(feat.OUTPUT_LAYOUT)
    fut = np.radians(300) * (np.arange(1, KEYS + 1) / KEYS)
    x, y = np.zeros((3, feat.LEADER_INPUT_SIZE)), np.zeros((3, feat.OUTPUT_SIZE))
    x[:, si["self_trajectory_past"]] = np.tile([0, 0, 0, 1], KEYS)
    x[2, si["partner_trajectory_past"]] = np.tile([0, 0, 0, 1], KEYS)       # hers: no bearing on his
    y[:, so["trajectory_future"]] = np.tile([0, 0, 0, 1], KEYS)
    y[0, so["trajectory_future"]] = np.stack([0 * fut, 0 * fut, np.sin(fut), np.cos(fut)], -1).ravel()
    assert T.own_turn_onsets(x, y, "leader").tolist() == [True, False, False]
    assert T.own_onset_weights(T.TrainConfig(own_turn_weight=4.0), x, y, "leader").tolist() == [4.0, 1.0, 1.0]
    assert T.own_onset_weights(T.TrainConfig(), x, y, "leader").tolist() == [1.0, 1.0, 1.0]
    xf = np.zeros((3, feat.INPUT_SIZE))
    xf[:, feat.block_slices(feat.FOLLOWER_INPUT_LAYOUT)["self_trajectory_past"]] = np.tile([0, 0, 0, 1], KEYS)
    assert T.own_turn_onsets(xf, y, "follower").tolist() == [True, False, False]   # her rule, her blocks
    assert T.own_onset_weights(T.TrainConfig(own_turn_weight=4.0), xf, y, "follower").tolist() == [1.0, 1.0, 1.0]


def test_lead_runs_on_freshly_exported_models(exported, data3, tmp_path, capsys):
    """The tool runs to its report on smoke models (whose dancing means nothing)."""
    out = tmp_path / "lead"
    rc = lead.main(["--models", str(exported["models"]), "--data", str(data3), "--takes", "06",
                    "--seeds", "2", "--seconds", "9", "--out", str(out), "--quiet"])
    assert rc == 0
    res = json.loads((out / "lead.json").read_text())
    assert res["summary"]["requests"] == 2                          # one at 3 s in each 9 s duet
    # The lead detector read both branches of every request (fitted on the 3 takes of data3).
    assert all(isinstance(r[k], bool) for s in res["per_seed"] for r in s["requests"]
               for k in ("lead_seen", "lead_seen_unasked"))
    text = capsys.readouterr().out
    assert "Does he lead?" in text
    # His own facing over each request, signed the asked way, and its median in the report.
    his = [r["his_turn"] for s in res["per_seed"] for r in s["requests"]]
    assert len(his) == 2 and all(np.isfinite(his))
    assert res["summary"]["his_turn"] == pytest.approx(float(np.median(his)))
    assert f"His own facing over a request: a median {res['summary']['his_turn']:+.0f} degrees" in text


def test_the_film_dances_the_duet_the_table_measured(exported):
    """unasked_duet (what scripts/worst_seed.py --nobody-steering films) is one_duet's duet of the
    same seed: the same figures; asked for a turn, it is the same duet until the request."""
    import argparse

    from training.evaluation import figures as Fg
    from training.evaluation import options as O
    from training.evaluation.evaluate_inputs import find_models, load_onnx

    manifest, onnx, leader_path = find_models(exported["models"])
    args = argparse.Namespace(temperature=None, follower_temperature=None, guard=None, guard_margin=None,
                              leader_guard=None)
    assert O.resolve(args, manifest) is None
    leader = O.leader_policy(load_onnx(leader_path), manifest, args)
    follower = O.follower_policy(load_onnx(onnx["ours"]), manifest, args, args.temperature)
    table = lead.one_duet(manifest, leader, follower, args.temperature, 1, 9.0)
    film = lead.unasked_duet(manifest, leader, follower, args.temperature, 1, 9.0)
    for who in ("leader", "follower"):
        got = Fg.dancer(film[who])
        assert all(got[k] == pytest.approx(v) for k, v in table[who].items()), who
    assert film["leader_shown"].shape == film["leader"].shape == (9 * FPS, 17, 3)
    asked = lead.unasked_duet(manifest, leader, follower, args.temperature, 1, 9.0, ask=(4.0, -1))
    at = 4 * FPS
    assert np.array_equal(asked["leader"][:at], film["leader"][:at])
    assert not np.allclose(asked["leader"][at + FPS], film["leader"][at + FPS])


def test_lead_names_missing_models(tmp_path, capsys):
    assert lead.main(["--models", str(tmp_path), "--seeds", "1"]) == 2
    assert "manifest.json not found" in capsys.readouterr().err


def test_recorded_leads_reads_his_hands_around_her_turns(data3, capsys):
    """The numbers behind the page's lead, read from 3 recorded takes: mirrored, every turn has
    one of the other direction, so both directions report and wind opposite ways."""
    from training.evaluation import recorded_leads
    assert recorded_leads.main(["--data", str(data3)]) == 0
    out = capsys.readouterr().out
    assert "Her turns to her left (+1)" in out and "Her turns to her right (-1)" in out
    left, right = (int(line.rsplit("negative in ", 1)[1].split(" %")[0]) for line in out.splitlines() if "winds" in line)
    assert left + right == 100                      # mirrored copies wind the other way
    # His facing around her turns, signed her way: each turn's mirrored copy turns her other way
    # and his with it, so the signed degrees come in the same amounts, whatever the way.
    turned, moved = recorded_leads.facing_around_turns(str(data3))
    assert len(turned) == len(moved) > 0 and len(turned) % 2 == 0 and np.all(moved >= 0)
    assert f"her way by a median {np.median(turned):+.0f} degrees" in out
    # The windows: her turns split by his hand, with shares that add up to the whole.
    r = recorded_leads.windows(str(data3))
    up, she = r[:, 0], r[:, 1]
    assert 0 < up.sum() < len(r) and she.mean() == pytest.approx((she[up].sum() + she[~up].sum()) / len(r))
    assert f"In {len(r)} windows of 2.5 s" in out
    # The recorded couple read as requests: with his hand up against all windows, and a follower
    # who turned after every raise: never below her share with his hand up.
    recorded, every = recorded_leads.request_contrast(r)
    assert recorded == pytest.approx(she[up].mean() / she.mean()) and every >= recorded
    assert f"she turns {recorded:.2f}x as often" in out
    assert np.isnan(recorded_leads.request_contrast(r[~r[:, 1]])[0])     # no turn: no ratio


def test_recorded_leads_names_a_folder_without_takes(tmp_path, capsys):
    from training.evaluation import recorded_leads
    assert recorded_leads.main(["--data", str(tmp_path)]) == 2
    assert "error" in capsys.readouterr().err


def test_page_figures_measures_a_dump_as_figures_measures_the_recording(data3, tmp_path, capsys):
    """training.evaluation.page_figures on a dump of the recorded take 06 itself (as the probe writes
    the page's duets): every rate is 1.0x the recording of take 06, and bad dumps are named."""
    import json

    import numpy as np

    from training.evaluation import page_figures
    from training.evaluation.evaluate_inputs import load_eval_takes

    take = load_eval_takes(str(data3), ["06"], None, None)[0]
    seed = {"seed": 7, "leader": take.lead.positions.reshape(len(take.lead.positions), -1).tolist(),
            "follower": take.follow.positions.reshape(len(take.follow.positions), -1).tolist()}
    dump = tmp_path / "probe.json"
    dump.write_text(json.dumps({"fps": 30, "seconds": len(take.lead.positions) / 30, "seeds": [seed]}))
    assert page_figures.main([str(dump), "--data", str(data3), "--takes", "06", "--out", str(tmp_path / "out")]) == 0
    res = json.loads((tmp_path / "out" / "page_figures.json").read_text())
    for who in ("leader", "follower"):
        for k, v in res["summary"][who]["ratio"].items():
            assert v is None or np.isnan(v) or v == pytest.approx(1.0), (who, k, v)
        assert res["summary"][who]["worst_seed"] == 7
        assert res["summary"][who]["median_turns_per_min"] == pytest.approx(res["recording"][who]["turns_per_min"])
    assert "seed 7" in capsys.readouterr().out
    far = np.linalg.norm(take.lead.positions[:, 0, [0, 2]] - take.lead.positions[0, 0, [0, 2]], axis=-1).max()
    assert res["summary"]["leader_from_start_m"]["max"] == pytest.approx(far)

    assert "rhythm" not in res                 # a dump without the count: no rhythm

    # With the count each step danced on (as the probe records it) and the networks' bodies beside
    # the drawn ones, the page's rhythm is rhythm.py's of the same take (after its first second, as
    # rhythm reads its duets).
    from training.evaluation import rhythm as R
    counted = {**seed, "beat": take.lead.beat.tolist(), "tempo": R.bpm_of(take.lead.beat),
               "leaderOwn": seed["leader"], "followerOwn": seed["follower"]}
    dump.write_text(json.dumps({"fps": 30, "seconds": len(take.lead.positions) / 30, "seeds": [counted]}))
    assert page_figures.main([str(dump), "--data", str(data3), "--takes", "06", "--out", str(tmp_path / "out")]) == 0
    res = json.loads((tmp_path / "out" / "page_figures.json").read_text())
    after = slice(30, None)
    own = R.rhythm(take.lead.positions[after], take.follow.positions[after], take.lead.beat[after], R.bpm_of(take.lead.beat))
    for body in R.BODIES:
        for role in ("leader", "follower"):
            assert res["rhythm"][body][role]["on_beat"] == pytest.approx(own[f"{role}_on_beat"])
    assert "on the beat" in capsys.readouterr().out
    counted["beat"] = counted["beat"][:-1]
    dump.write_text(json.dumps({"fps": 30, "seeds": [counted]}))
    assert page_figures.main([str(dump), "--data", str(data3), "--takes", "06"]) == 2
    assert "steps of the count" in capsys.readouterr().err

    short = tmp_path / "short.json"
    short.write_text(json.dumps({"fps": 30, "seeds": [{**seed, "leader": seed["leader"][:20]}]}))
    assert page_figures.main([str(short), "--data", str(data3)]) == 2
    assert "at least 5 s" in capsys.readouterr().err
    assert page_figures.main([str(tmp_path / "none.json"), "--data", str(data3)]) == 2
    assert "figures_probe.mjs" in capsys.readouterr().err


def test_his_own_turn_turns_his_planned_path_a_full_turn_without_a_side_step():
    duet = manifest_duet(figures=False)
    led = ro.figure_from(duet, 0, "his_turn", -1, False)
    duet.figures.led = [led]
    duet.frame = led.start
    t = duet.leader.track
    root, heading = t.root.copy(), t.heading.copy()
    ro.lead_plan(duet)
    keys = ro.NOW + FUTURE_OFFSETS
    share = np.array([ro.figure_share(led, led.start + o) for o in FUTURE_OFFSETS])
    assert np.allclose(t.heading[keys] - heading[keys], -2 * np.pi * share)
    assert np.array_equal(t.root, root)
    assert ro.hands_input(duet) is None                    # his own turn raises no lead hand


def test_a_branch_leaves_the_choosers_on_the_count_as_it_found_them(exported):
    """The policies are not copied with a duet: a branch (the asked or the unasked window) puts back
    what the choosers on the count saw, so the unasked window dances as if no asked one came first."""
    import argparse

    from training.evaluation import options as O
    from training.evaluation.evaluate_inputs import find_models, load_onnx

    manifest, onnx, leader_path = find_models(exported["models"])
    args = argparse.Namespace(temperature=None, follower_temperature=None, guard=4, guard_margin=None,
                              leader_guard=4, on_count=4)
    assert O.resolve(args, manifest) is None
    leader = O.leader_policy(load_onnx(leader_path), manifest, args)
    follower = O.follower_policy(load_onnx(onnx["ours"]), manifest, args, args.temperature)
    assert leader.on_count is not None and follower.on_count is not None
    duet = ro.start_duet(manifest, figures=False, seed=3)
    rng = np.random.default_rng(3)
    for _ in range(FPS):
        ro.step(duet, leader, follower, np.zeros(2), args.temperature, rng)
    seen = (leader.on_count.mean, follower.on_count.mean)

    def unasked():
        return lead.branch(duet, leader, follower, args.temperature, np.random.default_rng(7), None, FPS)[0]

    alone = unasked()
    assert (leader.on_count.mean, follower.on_count.mean) == seen
    lead.branch(duet, leader, follower, args.temperature, np.random.default_rng(7), 1, FPS)
    assert (leader.on_count.mean, follower.on_count.mean) == seen
    assert np.array_equal(unasked(), alone)


SHIPPED = Path(__file__).resolve().parents[2] / "public" / "models"


@pytest.mark.skipif(not (SHIPPED / "manifest.json").exists(), reason="no shipped models")
def test_each_seed_dances_as_if_alone(tmp_path):
    """A seed danced after another (`--first-seed 0 --seeds 2`) is the seed danced on its own, in
    lead and in jitter: each duet starts its choosers on the count afresh (options.restart_count),
    not from the footwork the duet before left them. The shipped models, whose samples stand, so
    that the choice on the count is what takes each step."""
    import argparse

    from training.evaluation import jitter
    from training.evaluation import options as O
    from training.evaluation.evaluate_inputs import find_models, load_onnx

    manifest, onnx, leader_path = find_models(SHIPPED)
    args = argparse.Namespace(temperature=None, follower_temperature=None, guard=None, guard_margin=None,
                              leader_guard=None)
    assert O.resolve(args, manifest) is None
    leader = O.leader_policy(load_onnx(leader_path), manifest, args)
    follower = O.follower_policy(load_onnx(onnx["ours"]), manifest, args, args.temperature)
    assert leader.on_count is not None and follower.on_count is not None
    alone = lead.one_duet(manifest, leader, follower, args.temperature, 1, 2.0)
    lead.one_duet(manifest, leader, follower, args.temperature, 0, 2.0)
    assert lead.one_duet(manifest, leader, follower, args.temperature, 1, 2.0) == alone

    def seed_1(first: int, seeds: int) -> dict:   # jitter's duets (without its recording's figures)
        ja = argparse.Namespace(models=str(SHIPPED), follower="follower", seeds=seeds, first_seed=first,
                                seconds=2.0, tempo=None, quiet=True, temperature=None, follower_temperature=None,
                                guard=None, guard_margin=None, leader_guard=None)
        return next(r for r in jitter.rollouts(ja, True) if r["seed"] == 1)

    assert seed_1(0, 2) == seed_1(1, 1)
