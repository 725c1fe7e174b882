#!/bin/sh
# The FOC drive's files and figures (issue 32), for each tuning in benchmarks/actuators/foc-*.toml:
# the monitor's calibration, the interval calibration (drawn drives), the detection thresholds,
# then benchmarks/bench_foc.py with them. About 25 min per tuning on 2 cores.
#
#     sh benchmarks/run_foc.sh [textbook stiff]
set -e
cd "$(dirname "$0")/actuators"
for tuning in ${*:-textbook stiff}; do
    a=foc-$tuning
    emaphm calibrate --params $a.toml --output $a.cal.json
    emaphm calibrate-uq --params $a.toml --calibration $a.cal.json --output $a.uq.json
    emaphm calibrate-detection --params $a.toml --calibration $a.cal.json --output $a.det.json
    python ../bench_foc.py --params $a.toml --calibration $a.cal.json --uq-calibration $a.uq.json \
        --detection $a.det.json --healthy 6
done
