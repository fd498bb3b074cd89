#!/usr/bin/env bash
# run_on_ranks.sh RUNOUT RANKS_CHECK RANKS SCENARIO [CHECK...]: the scenario run by `mpirun -n 1
# runout run` (one rank: the one-process run) and by `mpirun -n RANKS runout run`, then
# ranks_check's comparison (label mpi).
set -euo pipefail
runout=$1 check=$2 ranks=$3 scenario=$4
shift 4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
. "$(dirname "$0")/mpi_env.sh"
mpirun -n 1 "$runout" run "$scenario" --out "$work/one" --quiet
mpirun --oversubscribe -n "$ranks" "$runout" run "$scenario" --out "$work/many" --quiet
"$check" "$work/one" "$work/many" "$ranks" "$@"
