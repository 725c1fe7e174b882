# Study, not a benchmark (issue 34): what a current sensor's gain error does to the diagnosis and its
# verdict; docs/your-actuator.md §6 quotes it.
"""The Table 1 case identified with its current scaled by a sensor gain g (default settings).

    python studies/current_gain_verdict.py [--gains 1.0,1.05,1.1,1.2] [--seed 1]

The twin's Table 1 recording (noise seed from --seed, as ``emaphm identify --true-faults ... --seed S``
draws it) with i_q × g, identified with --seed; printed per gain: the verdict, the fit NRMSE, %err,
the faults detected and the first words of each reason for "doubtful".
"""

from __future__ import annotations

import argparse

import emaphm
from emaphm.identification.recording import split_seed
from emaphm.results import SimResult


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gains", default="1.0,1.05,1.1,1.2")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)
    truth = emaphm.TABLE1_REFERENCE
    twin = emaphm.simulate(truth, seed=split_seed(args.seed)[0])
    for gain in (float(g) for g in args.gains.split(",")):
        recording = SimResult(t=twin.t, signals={**twin.signals, "i_q": gain * twin.signals["i_q"]})
        r = emaphm.identify(reference=recording, seed=args.seed)
        print(f"gain {gain:.3g}: {r.verdict}, fit {100 * r.fit_nrmse:.2f} %, %err "
              f"{emaphm.percent_error(r.estimate, truth):.2f}, detected {', '.join(r.detected) or '-'}"
              + "".join(f"\n    {d[:70]}..." for d in r.doubts), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
