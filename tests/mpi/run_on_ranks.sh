#!/usr/bin/env bash
# run_on_ranks.sh RUNOUT RANKS_CHECK RANKS SCENARIO [CHECK...]: the scenario run by `mpirun -n 1
# runout run` (one rank: the one-process run) and by `mpirun -n RANKS runout run`, then
# ranks_check's comparison (label mpi).
set -euo pipefail
runout=$1 check=$2 ranks=$3 scenario=$4
shift 4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1 OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none  # (a container without ptrace refuses cross-memory attach)
export OMPI_MCA_mpi_yield_when_idle=1  # (a waiting rank gives its core to the others: 4 ranks share 2 cores with other tests)
mpirun -n 1 "$runout" run "$scenario" --out "$work/one" --quiet
mpirun --oversubscribe -n "$ranks" "$runout" run "$scenario" --out "$work/many" --quiet
"$check" "$work/one" "$work/many" "$ranks" "$@"
