"""Multi-fault identification (issue 8): accuracy, wrong basins and time on random actuators.

    python benchmarks/bench_multifault.py [--cases 40] [--seeds 2] [--restarts 3] [--case-seed 2611]
                                          [--monitor default|paper] [--command chirp|chirp-2s|chirp-hold|steps]
                                          [--params ACTUATOR.toml --calibration CAL.json]
                                          [--last-stage auto|switching|none]

Smallest run (the smoke test): ``--cases 1 --seeds 1 --restarts 0 --pop-size 4 --generations 1
--no-polish --last-stage none``. Reported in BENCHMARKS.md, "Multi-fault identification" (and
"Another actuator" with --params/--calibration).

Cases: DESIGN §7 ranges (`emaphm.faults.random_faults`) drawn from --case-seed, a seed of this
script's own (the calibration and `bench_identify.py` use others). Each case is identified with
seeds 1..--seeds exactly as ``emaphm identify --true-faults K --seed S`` does: seed S is split
into the twin's noise seed (a fresh measurement per seed) and the optimiser's seed. --command runs
the twin under another of the calibration's commands (the trace is then identified as a recording,
``emaphm identify --reference``); --monitor picks the monitor model (the paper's, eqs. 1-2 alone, or
the default one). --params and --calibration run another actuator (an actuator file, issue 10) on
its own twin with its own calibration (``emaphm calibrate --params``). --last-stage is identify's
(the switching last stage, `emaphm.identification.last_stage`; "auto": with the default monitor).
The research flags --starts and --best-from are gone (last at dae85bf; their figures are in
benchmarks/results/HISTORY.md).

Printed per case and in summary:
- LF-vs-HF NRMSE at the truth (noise off, 150 Hz filtered): the monitor's bias for that actuator,
  over the whole trace and ("cmp") over the samples the identification compares; in the summary
  also the switching model's (`switching.SwitchingModel`, the model the last stage fits with)
  against the twin over the compared samples;
- %err of each run, median / p90 / max over all runs, and runs above 10 %err;
- wrong basins: a run whose search's fitness (the monitor's eq. 3 at the search's estimate, before
  any last stage) exceeds 1.2x the best fitness found for its measurement by a reference search
  (the run itself plus --restarts more identifications of the same measurement with other
  optimiser seeds); also the fitness at the true vector, to tell model bias (truth worse than the
  estimate) from search failure;
- wall time per identification.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from _cases import (  # benchmarks/ is the script's folder, first on sys.path
    BUDGET,
    CALIBRATION_COMMANDS,
    SECOND_SEARCH_NRMSE,
    SampledCommand,
    SwitchingModel,
    add_settings,
    budget_text,
    draw_cases,
    machine_line,
    measure,
    params_hash,
    resolve_params,
    settings_of,
    spread,
)

import emaphm
from emaphm.identification import Comparison
from emaphm.identification import nrmse as nrmse_of

# the identification's settings this benchmark sets (flags made from `IdentifySettings`)
SETTINGS = (*BUDGET, "optimizer", "start", "monitor", "last_stage")


def fitness_at(trace: emaphm.SimResult, K: np.ndarray, monitor: emaphm.MonitorEma) -> np.ndarray:
    """Eq. (3) fitness of fault rows K on a measured trace: the identification's own objective
    (the same grid, filter and compared samples, `FaultIdentifier.prepare`)."""
    command = SampledCommand(trace.t - trace.t[0], trace.theta_cmd)
    ident = emaphm.FaultIdentifier(monitor=monitor).prepare(trace.t, trace.i_q, command, trace.theta_u)
    return ident.objective_.of_monitor(ident.monitor_, K, duration=ident.duration_)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--restarts", type=int, default=3, help="extra optimiser seeds per measurement")
    parser.add_argument("--case-seed", type=int, default=2611)
    parser.add_argument("--command", default="chirp", choices=tuple(CALIBRATION_COMMANDS))
    parser.add_argument("--params", default=None, help="actuator file (default: the nominal actuator)")
    parser.add_argument("--calibration", default=None, help="its LF calibration (default: the packaged one)")
    add_settings(parser, SETTINGS)
    args = parser.parse_args(argv)
    params = resolve_params(args.params)
    print(machine_line(
        f"{args.cases} cases (seed {args.case_seed}) x {args.seeds} seeds, {args.restarts} restarts, "
        f"optimizer {args.optimizer}, monitor {args.monitor}, command {args.command}, {budget_text(args)}; "
        f"actuator {args.params or 'nominal'} ({params_hash(params)}), calibration {args.calibration or 'packaged'}, "
        f"last stage {args.last_stage}"))  # fmt: skip
    cases = draw_cases(args.cases, args.case_seed)
    command = CALIBRATION_COMMANDS[args.command]
    monitor = emaphm.MonitorEma(params, command, args.calibration, monitor=args.monitor)
    hf = emaphm.HighFidelityEma(params, command)
    errs, walls, wrong, bias_runs, nrmses, nrmses_cmp = [], [], 0, 0, [], []
    fits, second_runs, second_taken, evaluations = [], 0, 0, []
    switching, nrmses_switching, stage_taken = SwitchingModel(params, command), [], 0
    print(
        f"{'case':>4} {'NRMSE':>6} {'cmp':>6} {'seed':>4} {'%err':>6} {'f_run':>8} {'f_best':>8} {'f_true':>8} {'fit':>6} {'wall':>5} {'evals':>5}  shorts"
    )
    for j, k in enumerate(cases):
        clean = hf.simulate(k, noise=False)
        ref = Comparison.from_signal(clean.t, clean.i_q, hf.params.controller.f_s)
        nrmse = float(ref.nrmse(monitor.simulate(k).i_q))
        nrmses.append(nrmse)
        # the same over the samples the identification compares (holds at rest and motion above
        # the monitor's band left out; 1 s chirp: all of them)
        seen = emaphm.FaultIdentifier(monitor=monitor).prepare(
            clean.t, clean.i_q, SampledCommand(clean.t - clean.t[0], clean.theta_cmd), clean.theta_u
        )
        keep = seen.mask_ > 0
        at_truth = seen.reference_.filtered(seen.monitor_.simulate(k, duration=seen.duration_).i_q)
        nrmses_cmp.append(float(nrmse_of(seen.reference_.reference[keep], at_truth[keep])))
        sw_truth = seen.reference_.filtered(switching.current(k, duration=seen.duration_, workers=2))
        nrmses_switching.append(float(nrmse_of(seen.reference_.reference[keep], sw_truth[keep])))
        for s in range(1, args.seeds + 1):
            trace = measure(k, s, hf)  # as identify(true_faults=k, seed=s) measures it
            t0 = time.perf_counter()
            run = emaphm.identify(
                reference=trace, seed=s, params=params, calibration=monitor.calibration, **settings_of(args, SETTINGS)
            )
            walls.append(time.perf_counter() - t0)
            evaluations.append(run.evaluations)
            err = emaphm.percent_error(run.estimate, k)
            errs.append(err)
            others = [
                emaphm.identify(
                    reference=trace, seed=1000 * r + s, params=params, calibration=monitor.calibration,
                    **settings_of(args, SETTINGS),
                ).settings["search_fitness"]
                for r in range(1, args.restarts + 1)
            ]
            # basins are told apart by the search's own fitness (the monitor's eq. 3 at its estimate,
            # before any last stage): the switching model's eq. 3 differs by tens of per cent
            # between nearby estimates (its stick-slip is chaotic) and cannot rank them
            f_run = run.settings["search_fitness"]
            f_best = min([f_run, *others])
            f_true = float(fitness_at(trace, k[None, :], monitor)[0])
            is_wrong = f_run > 1.2 * f_best
            fits.append(run.fit_nrmse)
            second = run.stage("second_search")
            second = second if second["ran"] else None
            second_runs += second is not None
            second_taken += second is not None and second["taken"]
            mark = (
                ""
                if second is None
                else f"  2nd search {'taken' if second['taken'] else 'not taken'} (first fit {100 * second['first_fit_nrmse']:.2f}%)"
            )
            stage = run.stage("last_stage")["switching"]
            stage_taken += bool(stage and stage["taken"])
            mark += "" if stage is None else f"  stage {'taken' if stage['taken'] else 'not taken'}"
            wrong += is_wrong
            bias_runs += f_true > f_run
            print(f"{j:>4} {100 * nrmse:>5.2f}% {100 * nrmses_cmp[-1]:>5.2f}% {s:>4} {err:>6.2f} {f_run:>8.4f} {f_best:>8.4f} {f_true:>8.4f} "
                  f"{100 * run.fit_nrmse:>5.2f}% {walls[-1]:>5.1f} {run.evaluations:>5}  {k[2]:.2f} {k[3]:.2f} {k[4]:.2f}" + ("  WRONG BASIN" if is_wrong else "") + mark,
                  flush=True)  # fmt: skip
    n = len(errs)
    print()
    print(f"LF-vs-HF NRMSE at the truth: {spread(nrmses, 100, ' %')}")  # fmt: skip
    print(f"the same over the compared samples: {spread(nrmses_cmp, 100, ' %')}")  # fmt: skip
    print(f"the switching model against the twin there: {spread(nrmses_switching, 100, ' %')}")  # fmt: skip
    print(f"%err over {n} runs: {spread(errs)}; runs above 10 %err: {sum(e > 10 for e in errs)}")  # fmt: skip
    print(f"wrong basins (the search's fitness > 1.2x the best found for the measurement): {wrong} of {n}; "
          f"runs whose estimate fits better than the truth (model bias): {bias_runs} of {n}")  # fmt: skip
    print(f"fit NRMSE over the compared samples: {spread(fits, 100, ' %')}; "
          f"second searches (fit above {100 * SECOND_SEARCH_NRMSE[monitor.monitor]:g} %): {second_runs} of {n}, taken {second_taken}")  # fmt: skip
    print(f"switching last stage ({args.last_stage}) moved the estimate in {stage_taken} of {n} runs")
    print(f"wall time per identification: median {statistics.median(walls):.1f} s, max {max(walls):.1f} s")
    print(f"monitor evaluations per identification: {spread(evaluations, digits=0)}")


if __name__ == "__main__":
    main()
