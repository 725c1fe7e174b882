"""Prognostics on simulated run-to-failure histories (issue 12): alpha-lambda, coverage, horizon.

    emaphm campaign run benchmarks/campaigns/rtf.toml --out STORE      # 285 identifications
    python benchmarks/bench_rul.py STORE [--alpha 0.2] [--lam 0.5] [--estimator trend|ukf]

Smallest run (the smoke test): a store of one actuator flown a few flights with a tiny budget
(tests/test_benchmarks.py writes its spec), ``STORE --spec SPEC``. Reported in BENCHMARKS.md,
"Prognostics".

The campaign flies 10 actuators on the HF twin (noise on) whose friction and backlash grow
linearly from flight 1 (start 0.05 and 0.02, growth drawn per actuator, `rtf.toml`); every flight
is identified with its 90 % intervals. With the thresholds friction 0.45 and backlash 0.25 the
true crossing flight is T* = 1 + (threshold - start)/growth, known exactly. For each actuator and
fault, `emaphm.prognostics.rul_report` is asked at every stored flight after the onset (its
first detection):

- at lambda = 50 % of life (the flight onset + lam*(T* - onset)): is the median RUL within
  alpha of the true RUL (alpha-lambda), does the 5-95 % range hold the true RUL, and the relative
  accuracy 1 - |RUL - true|/true;
- the prognostic horizon: T* minus the first flight from which every later prediction stays
  within alpha*(T* - onset) of the truth, as a fraction of the life T* - onset.
The definitions are those of Saxena et al. (IJPHM 2010). Where ProgPy is installed
(``emaphm[progpy]``), ProgPy's own metrics are computed too on the same predictions (a
``ToEPredictionProfile`` of every prediction's draws): its α-λ (at least beta = 50 % of the
draws within alpha of the true RUL, at the first prediction at or after lambda), its prognostic
horizon (with the criterion "the median within alpha of the life", as a fraction of the life) and
its cumulative relative accuracy (of the time of event, as ProgPy defines it).
"""

from __future__ import annotations

import argparse
import math
import statistics
import tomllib
from pathlib import Path

from _cases import progpy_model as load_progpy  # benchmarks/ is the script's folder, first on sys.path

from emaphm import InputError
from emaphm.prognostics import rul_report

HERE = Path(__file__).resolve().parent
THRESHOLDS = {"friction": 0.45, "backlash": 0.25}
COLUMN = {"friction": 0, "backlash": 1}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("store", type=Path)
    parser.add_argument("--spec", type=Path, default=HERE / "campaigns" / "rtf.toml")
    parser.add_argument("--alpha", type=float, default=0.2)
    parser.add_argument("--lam", type=float, default=0.5)
    parser.add_argument("--estimator", default="trend", choices=("trend", "ukf"))
    parser.add_argument("--include-doubtful", action="store_true", help='track "doubtful" diagnoses too')
    args = parser.parse_args(argv)
    progpy_model = load_progpy()
    pp_met, pp_ph, pp_cra = 0, [], []
    spec = tomllib.loads(args.spec.read_text())
    met, covered, accuracy, horizons, n = 0, 0, [], [], 0
    print(f"{'actuator':>8} {'fault':>9} {'T*':>6} {'onset':>5} {'at':>4} {'true':>6} {'median':>6} "
          f"{'5-95 %':>13} {'a-l':>4} {'PH/life':>7}")  # fmt: skip
    for act in spec["actuator"]:
        for fault, threshold in THRESHOLDS.items():
            j = COLUMN[fault]
            start, growth = act["start"][j], act["growth"][j]
            t_star = 1.0 + (threshold - start) / growth
            try:
                report = rul_report(args.store, act["id"], thresholds=THRESHOLDS, estimator=args.estimator,
                                    include_doubtful=args.include_doubtful)  # fmt: skip
            except InputError as exc:  # a campaign not run to its end
                print(f"{act['id']:>8} {fault:>9}  {exc}")
                continue
            onset = report["faults"][fault].get("tracked_from")
            if onset is None:
                print(f"{act['id']:>8} {fault:>9} {t_star:6.1f}  never detected")
                continue
            last = min(int(report["at_flight"]), math.ceil(t_star) - 1)  # predictions before the end of life
            predictions, draws = {}, {}
            for flight in range(int(onset) + 1, last + 1):
                r = rul_report(
                    args.store, act["id"], at_flight=flight, thresholds=THRESHOLDS, estimator=args.estimator,
                    include_doubtful=args.include_doubtful,
                )
                f = r["faults"][fault]
                if f.get("rul_median") is not None:
                    predictions[flight] = f
                    draws[flight] = {fault: flight + r["_estimates"][fault].samples}
            at = round(onset + args.lam * (t_star - onset))
            if at not in predictions:
                print(f"{act['id']:>8} {fault:>9} {t_star:6.1f} {onset:>5}  no prediction at flight {at}")
                continue
            n += 1
            p = predictions[at]
            true = t_star - at
            ok = abs(p["rul_median"] - true) <= args.alpha * true
            inside = (
                p["rul_p05"] is not None and p["rul_p95"] is not None and p["rul_p05"] <= true <= p["rul_p95"]
            )
            met += ok
            covered += inside
            accuracy.append(1.0 - abs(p["rul_median"] - true) / true)
            width = args.alpha * (t_star - onset)
            good = [fl for fl, q in predictions.items() if abs(q["rul_median"] - (t_star - fl)) <= width]
            first = next((fl for fl in sorted(predictions) if all(g in good for g in range(fl, last + 1)
                                                                   if g in predictions)), None)  # fmt: skip
            ph = 0.0 if first is None else (t_star - first) / (t_star - onset)
            horizons.append(ph)
            if progpy_model is not None:
                profile = progpy_model.toe_profile(draws, never=10 * t_star)
                m = progpy_model.progpy_metrics(profile, {fault: t_star}, lambda_value=at, alpha=args.alpha,
                                                onset=onset)[fault]  # fmt: skip
                pp_met += m["alpha_lambda"]
                pp_ph.append(
                    0.0 if m["prognostic_horizon"] is None else m["prognostic_horizon"] / (t_star - onset)
                )
                pp_cra.append(m["cra"])
            band = "-".join("     -" if v is None else f"{v:6.1f}" for v in (p["rul_p05"], p["rul_p95"]))
            print(f"{act['id']:>8} {fault:>9} {t_star:6.1f} {onset:>5} {at:>4} {true:6.1f} {p['rul_median']:6.1f} "
                  f"{band} {'yes' if ok else 'no':>4} {ph:7.2f}")  # fmt: skip
    print()
    print(f"alpha-lambda (alpha {args.alpha:g}, lambda {100 * args.lam:g} % of life) met: {met} of {n} "
          f"({100 * met / max(n, 1):.0f} %); true RUL inside the 5-95 % range: {covered} of {n} "
          f"({100 * covered / max(n, 1):.0f} %)")  # fmt: skip
    if accuracy:
        print(f"relative accuracy at lambda: median {statistics.median(accuracy):.3f}, min {min(accuracy):.3f}; "
              f"prognostic horizon (fraction of life): median {statistics.median(horizons):.2f}, "
              f"min {min(horizons):.2f}")  # fmt: skip
    if progpy_model is not None and pp_cra:
        print(f"ProgPy's metrics: alpha-lambda (beta 0.5) met {pp_met} of {len(pp_cra)}; prognostic horizon "
              f"(fraction of life) median {statistics.median(pp_ph):.2f}, min {min(pp_ph):.2f}; cumulative "
              f"relative accuracy median {statistics.median(pp_cra):.3f}, min {min(pp_cra):.3f}")  # fmt: skip
    elif progpy_model is None:
        print("ProgPy's metrics: not computed (pip install 'emaphm[progpy]')")
    print(f"estimator: {args.estimator}")


if __name__ == "__main__":
    main()
