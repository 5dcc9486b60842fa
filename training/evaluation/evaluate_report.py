"""The reports of training.evaluation.evaluate: metrics.md (the headline table, the free-running
and the controlled runs) and the JSON beside it; interaction writes its report the same way."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np


def fmt(v, digits=2):
    if v is None:
        return "n/a"
    if isinstance(v, int):
        return str(v)
    return f"{v:.{digits}f}" if abs(v) >= 10 ** -digits or v == 0 else f"{v:.2e}"


def pct(v):
    return "n/a" if v is None else f"{100 * v:.1f}"


def write_markdown(path: Path, res: dict) -> None:
    L = [f"# Evaluation: takes {', '.join(res['takes'])}", "",
         f"{res['frames']} evaluated frames (30 fps); models `{res['config']['models']}`; seeds "
         f"{res['config']['seeds']}, temperatures {res['config']['temperatures']} "
         f"(headline at {res['config']['headline_temperature']}); {res['config']['seconds']:.0f} s.", "",
         "## Headline (paper Table 1)", "",
         "MPJPE and codebook error: teacher-forced (a). The rest: free-running rollout (b), leader "
         "played back from the recording, mean over seeds. Diversity: closer to ground truth is better. "
         "Implausible: share of the follower's frames with its body low, folded or split; worst second: "
         "the largest share in any one second, worst over seeds and takes (evaluation.plausibility, "
         "against the training takes' range).", "",
         "| method | MPJPE cm ↓ | Diversity → | FID ↓ | Codebook ↓ | foot skate cm ↓ | jitter m/s³ | hand dist m "
         "| implausible % ↓ | worst second % ↓ |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for name, m in res["methods"].items():
        L.append(f"| {name} | {fmt(m.get('mpjpe_cm'))} | {fmt(m.get('diversity'))} | {fmt(m.get('fid'))} | "
                 f"{fmt(m.get('codebook_error'), 4)} | {fmt(m.get('foot_skate_cm'))} | {fmt(m.get('jitter'), 1)} | "
                 f"{fmt(m.get('hand_distance'))} | {pct(m.get('implausible'))} | {pct(m.get('worst_second'))} |")
    L += figures_table(res)
    tf = res["protocols"]["teacher_forced"]
    if "motion_matching_oracle" in tf:
        L += ["", f"Motion Matching queried with the recorded follower future (the paper's MM query; "
                  f"not available at run time): teacher-forced MPJPE "
                  f"{fmt(tf['motion_matching_oracle']['mpjpe_cm'])} cm."]
    L += ["", "## Free-running rollout (b)", "",
          "| method | temperature | MPJPE cm | root error m | FID | Diversity | foot skate cm | jitter "
          "| hand dist m | resets |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for name, r in res["protocols"]["rollout"].items():
        for temp, m in r["by_temperature"].items():
            L.append(f"| {name} | {temp} | {fmt(m['mpjpe_cm'])} | {fmt(m['root_error_m'])} | {fmt(m['fid'])} | "
                     f"{fmt(m['diversity'])} | {fmt(m['foot_skate_cm'])} | {fmt(m['jitter'], 1)} | "
                     f"{fmt(m['hand_distance'])} | {m['resets']:.0f} |")
    ctl = res["protocols"]["controlled"]
    if ctl:
        L += ["", f"## Controlled (c), temperature {res['config']['headline_temperature']}, seed "
                  f"{res['config']['seeds'][0]}", "",
              "playback:rot±A turns the leader's future keys (what the follower sees) by A degrees about "
              "the leader's root; side±M pushes them up to M metres along the leader's root-space x; mm / "
              "model: the leader is generated (Motion Matching over the training leaders / leader.onnx), "
              "steered along the recording's path from where it stands. FID drift = FID here minus FID "
              "in (b). Divergence: share of frames with the partners more than 3 m apart.", "",
              "| condition | method | foot skate cm | jitter | FID | FID drift | dist. to leader m "
              "| divergence | resets (follower+leader) |",
              "|---|---|---|---|---|---|---|---|---|"]
        for cond, per in ctl.items():
            for name, m in per.items():
                L.append(f"| {cond} | {name} | {fmt(m['foot_skate_cm'])} | {fmt(m['jitter'], 1)} | {fmt(m['fid'])} | "
                         f"{fmt(m['fid_drift'])} | {fmt(m['distance_to_leader'])} | {fmt(m['divergence'], 3)} | "
                         f"{m['resets']}+{m['leader_resets']} |")
    L += ["", "## Notes", ""] + [f"- {n}" for n in res["notes"]]
    path.write_text("\n".join(L) + "\n")


def figures_table(res: dict) -> list[str]:
    """The salsa figures of the headline runs against the recording (evaluation.figures): each
    rate with its ratio to the recorded follower's, and the lowest..highest seed."""
    ref = res["methods"].get("ground_truth", {})
    if "turns_per_min" not in ref:
        return []

    def cell(m, k, digits=2, share=False):
        v = m.get(k)
        if v is None:
            return "n/a"
        show = (lambda x: pct(x)) if share else (lambda x: fmt(x, digits))
        text = show(v)
        if ref.get(k) and k not in ("recall", "precision", "direction"):
            text += f" ({v / ref[k]:.2f}×)"
        if m.get(f"{k}_min") is not None and m.get(f"{k}_min") != m.get(f"{k}_max"):
            text += f" [{show(m[f'{k}_min'])}..{show(m[f'{k}_max'])}]"
        return text

    L = ["", "## Salsa figures (b)", "",
         "The follower's turns, spins, body motion and travel in the free-running runs beside the "
         "played-back leader, as a ratio to the recorded follower's, with the lowest..highest seed "
         "in brackets; recall and precision of its turns against the recorded follower's (same "
         "direction, within 0.75 s); the way: of its turns that meet a recorded one either way, the "
         "share that go the recorded way (the ceiling: training.evaluation.turn_direction).", "",
         "| method | turns/min | spin frames % | body motion m/s | travel m/s | turn recall % | turn precision % | the way % |",
         "|---|---|---|---|---|---|---|---|"]
    for name, m in res["methods"].items():
        L.append(f"| {name} | {cell(m, 'turns_per_min', 1)} | {cell(m, 'spin_frames', share=True)} | "
                 f"{cell(m, 'body_motion')} | {cell(m, 'travel')} | {cell(m, 'recall', share=True)} | "
                 f"{cell(m, 'precision', share=True)} | {cell(m, 'direction', share=True)} |")
    if "pulse" in ref:
        L += ["", "The follower's rhythm in the same runs, at the take's count found in its footwork (the "
              "count she hears; training.evaluation.rhythm): her footwork's pulse, her steps on the beat "
              "(mean cosine of the count's phase at her steps) and together (her motion beats within 0.1 s "
              "of the played-back leader's).", "",
              "| method | pulse | on the beat | together |", "|---|---|---|---|"]
        for name, m in res["methods"].items():
            L.append(f"| {name} | {cell(m, 'pulse')} | {rhythm_cell(m, 'on_beat')} | {cell(m, 'together')} |")
    return L


def rhythm_cell(m: dict, k: str) -> str:
    """A figure that can be negative (steps on the beat), so no ratio: the value and its seeds."""
    v = m.get(k)
    if v is None:
        return "n/a"
    text = f"{v:+.2f}"
    if m.get(f"{k}_min") is not None and m.get(f"{k}_min") != m.get(f"{k}_max"):
        text += f" [{m[f'{k}_min']:+.2f}..{m[f'{k}_max']:+.2f}]"
    return text


def clean(o):
    """JSON-safe: NaN/inf -> None, numpy scalars -> Python."""
    if isinstance(o, dict):
        return {k: clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [clean(v) for v in o]
    if isinstance(o, (np.floating, float)):
        return float(o) if math.isfinite(o) else None
    if isinstance(o, np.integer):
        return int(o)
    return o


def write_report(out: Path, stem: str, res: dict, markdown) -> dict:
    """out/STEM.json (JSON-safe) and out/STEM.md (written by `markdown`), which is printed too."""
    out.mkdir(parents=True, exist_ok=True)
    res = clean(res)
    (out / f"{stem}.json").write_text(json.dumps(res, indent=1, allow_nan=False))
    markdown(out / f"{stem}.md", res)
    print((out / f"{stem}.md").read_text())
    return res
