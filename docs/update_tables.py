"""Regenerate the tables in the docs that come from the code (run after changing parameters).

python docs/update_tables.py
"""

from __future__ import annotations

import re
from pathlib import Path

from emaphm.calibration import default_calibration
from emaphm.params import parameter_table_markdown

DOCS = Path(__file__).parent


def calibration_tables() -> str:
    """The packaged calibrations: coefficients, then NRMSE per scenario (fitted and held out)."""
    out = []
    for monitor in ("default", "paper"):
        cal = default_calibration(monitor)
        rec, c = cal.record, cal.coefficients
        st = rec["settings"]
        out.append(
            f"**{monitor} monitor** (`emaphm calibrate{' --monitor paper' if monitor == 'paper' else ''}`, "
            f"seed {rec['seed']}, {st['evaluations']} evaluations, {st['wall_time_s']:.0f} s, "
            f"made {rec['created'][:10]}): "
            + ", ".join(f"{k} = {v:.4g}" for k, v in vars(c).items())
            + f"; k_FT = {c.k_FT:.4g}; k_t,eq/J_eq = {c.k_t_eq / c.J_eq:.0f} A⁻¹·s⁻² "
            f"(nominal {0.15 / 5.125e-5:.0f}).\n"
        )
        noisy = {(s["name"], s["command"]): s["nrmse"] for s in rec.get("check_scenarios_noise_on", [])}
        first = {(s["name"], s["command"]): s["nrmse"] for s in rec["before_calibration"]["scenarios"]}
        before = "first guess" if st.get("held_from", "first guess") == "first guess" else "start"
        out.append(f"| scenario | command | role | NRMSE {before} | calibrated | calibrated, HF noise on |")
        out.append("|---|---|---|---|---|---|")
        for key, role in (("fit_scenarios", "fit"), ("check_scenarios", "held out")):
            for s in rec[key]:
                k = (s["name"], s["command"])
                on = f"{100 * noisy[k]:.2f} %" if k in noisy else ""
                out.append(
                    f"| {s['name']} | {s['command']} | {role} | {100 * first[k]:.2f} % | "
                    f"{100 * s['nrmse']:.2f} % | {on} |"
                )
        out.append("")
    return "\n".join(out) + "\n"


BLOCKS = {
    DOCS / "theory" / "hf-model.md": ("params", parameter_table_markdown),
    DOCS / "theory" / "monitor-model.md": ("calibration", calibration_tables),
}


def render(text: str, name: str, table: str) -> str:
    pattern = re.compile(rf"(<!-- {name}:start -->\n).*?(<!-- {name}:end -->)", re.S)
    if not pattern.search(text):
        raise SystemExit(f"no <!-- {name}:start/end --> markers")
    return pattern.sub(lambda m: m.group(1) + table + m.group(2), text)


def main() -> None:
    for path, (name, make) in BLOCKS.items():
        path.write_text(render(path.read_text(), name, make()))
        print(f"updated {path}")


if __name__ == "__main__":
    main()
