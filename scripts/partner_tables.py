"""Markdown tables of docs/results.md's "Partner dancing" from scripts/partner_terms.sh's output.

    .venv/bin/python scripts/partner_tables.py [runs/partner_interaction/interaction.json runs/partner_eval/metrics.json]
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

PROTOCOLS = [("teacher_forced", "teacher-forced"), ("free_running", "free-running"),
             ("free_running_layer", "free-running + layer"), ("steered", "steered"),
             ("steered_layer", "steered + layer")]
NAMES = {"ours": "ours", "ccm": "CCM", "motion_matching": "Motion Matching",
         "follower_no_partner_terms": "ours before (no partner terms)",
         "follower_no_penetration": "w/o penetration", "follower_no_foot_contact": "w/o foot contact",
         "follower_no_interaction": "w/o interaction",
         "follower_recorded_contact_30": "foot contact 30 (recorded contacts)",
         "follower_decoded_contact_5": "foot contact 5 on decoded contacts",
         "follower_decoded_contact_10": "foot contact 10 on decoded contacts",
         "follower_decoded_contact_30": "foot contact 30 on decoded contacts",
         "follower_decoded_contact_30_penetration_100": "foot contact 30 on decoded, penetration 100",
         "follower_tempo": "ours + tempo copies",
         "follower_ccm_tempo": "CCM + tempo copies",
         "follower_no_proximity": "ours w/o proximity",
         "follower_ccm_no_proximity": "CCM w/o proximity",
         "follower_interaction_hands_only": "w/o proximity, interaction on hands only"}
ORDER = ["ours", "ccm", "follower_no_partner_terms", "follower_no_penetration", "follower_no_foot_contact",
         "follower_no_interaction", "follower_recorded_contact_30", "follower_decoded_contact_5",
         "follower_decoded_contact_10", "follower_decoded_contact_30", "follower_decoded_contact_30_penetration_100"]


def pct(v: float) -> str:
    return f"{100 * v:.1f} %"


def cell(r: dict, ref: dict, k: str, fmt) -> str:
    return f"{fmt(r[k])} ({r[k] / ref[k]:.2f}×)" if ref[k] else fmt(r[k])


def interaction_table(res: dict, methods: list[str]) -> list[str]:
    ref = res["recording"]
    cols = [("interpenetration", pct), ("hand_hold", pct), ("closest_hand_m", lambda v: f"{v:.2f}"),
            ("contact_skate_leader_cm", lambda v: f"{v:.2f}"), ("contact_skate_follower_cm", lambda v: f"{v:.2f}"),
            ("skate_leader_cm", lambda v: f"{v:.2f}"), ("skate_follower_cm", lambda v: f"{v:.2f}")]
    L = ["| follower | protocol | torsos through each other | hands within 20 cm | closest hands m | "
         "skate in contact L / F cm | skate while low L / F cm |", "|---|---|---|---|---|---|---|",
         f"| recording | | {pct(ref['interpenetration'])} | {pct(ref['hand_hold'])} | {ref['closest_hand_m']:.2f} | "
         f"{ref['contact_skate_leader_cm']:.2f} / {ref['contact_skate_follower_cm']:.2f} | "
         f"{ref['skate_leader_cm']:.2f} / {ref['skate_follower_cm']:.2f} |"]
    for m in methods:
        for key, title in PROTOCOLS:
            r = res["methods"][m][key]
            c = {k: cell(r, ref, k, f) for k, f in cols}
            L.append(f"| {NAMES.get(m, m)} | {title} | {c['interpenetration']} | {c['hand_hold']} | "
                     f"{c['closest_hand_m']} | {c['contact_skate_leader_cm']} / {c['contact_skate_follower_cm']} | "
                     f"{c['skate_leader_cm']} / {c['skate_follower_cm']} |")
    return L


def terms_table(res: dict, ev: dict, methods: list[str]) -> list[str]:
    ref = res["recording"]
    L = ["| follower (partner terms) | MPJPE cm | FID | Diversity | steered: torsos through | hands within 20 cm | "
         "closest hands m | follower skate in contact / while low cm | + layer: through / hands / skate in contact |",
         "|---|---|---|---|---|---|---|---|---|"]
    for m in methods:
        e, s, sl = ev["methods"][m], res["methods"][m]["steered"], res["methods"][m]["steered_layer"]
        L.append(f"| {NAMES.get(m, m)} | {e['mpjpe_cm']:.2f} | {e['fid']:.1f} | {e['diversity']:.2f} | "
                 f"{pct(s['interpenetration'])} | {pct(s['hand_hold'])} | {s['closest_hand_m']:.2f} | "
                 f"{s['contact_skate_follower_cm']:.2f} / {s['skate_follower_cm']:.2f} | "
                 f"{pct(sl['interpenetration'])} / {pct(sl['hand_hold'])} / {sl['contact_skate_follower_cm']:.2f} |")
    L.append(f"| recording | | | {ev['methods']['ground_truth']['diversity']:.2f} | {pct(ref['interpenetration'])} | "
             f"{pct(ref['hand_hold'])} | {ref['closest_hand_m']:.2f} | "
             f"{ref['contact_skate_follower_cm']:.2f} / {ref['skate_follower_cm']:.2f} | |")
    return L


def steering_table(res: dict, methods: list[str]) -> list[str]:
    L = ["| follower | s to within 30° of a 90° turn | speed m/s |", "|---|---|---|"]
    for m in methods:
        s = res["methods"][m]["steering"]
        t = "never" if s["turn_seconds"] is None else f"{s['turn_seconds']:.2f}"
        L.append(f"| {NAMES.get(m, m)} | {t} ({s['turn_missed']} of {s['trials']} missed) | {s['speed']:.2f} |")
    return L


def main(argv: list[str]) -> int:
    inter = Path(argv[0] if argv else "runs/partner_interaction/interaction.json")
    evals = Path(argv[1] if len(argv) > 1 else "runs/partner_eval/metrics.json")
    res, ev = json.loads(inter.read_text()), json.loads(evals.read_text())
    shipped = [m for m in ("ours", "ccm", "motion_matching", "follower_no_partner_terms", "follower_no_proximity",
                           "follower_ccm_no_proximity", "follower_tempo", "follower_ccm_tempo")
               if m in res["methods"]]
    rows = [m for m in ORDER if m in res["methods"] and m in ev["methods"]]
    rows += [m for m in res["methods"] if m not in rows + ["motion_matching"] and m in ev["methods"]]
    print("\n".join(interaction_table(res, shipped)), "\n")
    print("\n".join(terms_table(res, ev, rows)), "\n")
    print("\n".join(steering_table(res, shipped)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
