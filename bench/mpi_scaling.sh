#!/usr/bin/env bash
# The 3D engine on 1 process (1 and 2 OpenMP threads) against 2 MPI ranks of 1 thread each, on the
# same machine in one go (docs/design/performance.md, "One 3D run over two processes"):
#   B2   scenarios/lab/b2-collapse-0deg.json as bundled (2.5 mm, 12,000 cells, plane) to 0.3 s
#   B7   scenarios/lab/b7-wide-chute-cylinder.json at 5 mm (165,128 cells) to 0.3 s
#   C1   scenarios/in-den-arelen-3d.json as bundled (30 m, the footprint corridor) to 10 s
# Each configuration REPEATS times (default 3); prints per case and configuration the median of the
# stepping loop's wall time, the steps, the mean active cells, the time per step and its ratio to one
# thread, and for 2
# ranks the split's ghost share and the halo's traffic per step (run.json, read by record_check).
# usage: bench/mpi_scaling.sh RUNOUT RECORD_CHECK [REPEATS]
set -euo pipefail
runout=$1 check=$2 repeats=${3:-3}
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# The cases' scenarios, cut to the measured window (the lab's grids and end times, the terrain's end time).
python3 - "$src" "$work" <<'PY'
import json, sys
src, work = sys.argv[1], sys.argv[2]
b2 = json.load(open(f"{src}/scenarios/lab/b2-collapse-0deg.json"))
b2["lab"]["end_time_s"] = 0.3
json.dump(b2, open(f"{work}/b2.json", "w"))
b7 = json.load(open(f"{src}/scenarios/lab/b7-wide-chute-cylinder.json"))
for k in ("nx", "ny", "nz"): b7["lab"][k] //= 2
b7["lab"]["end_time_s"] = 0.3
json.dump(b7, open(f"{work}/b7.json", "w"))
c1 = json.load(open(f"{src}/scenarios/in-den-arelen-3d.json"))
c1["numerics"]["end_time_s"] = 10
for k in ("dem", "area_of_interest"): c1[k]["path"] = f"{src}/scenarios/" + c1[k]["path"]
for r in c1["releases"]: r["path"] = f"{src}/scenarios/" + r["path"]
json.dump(c1, open(f"{work}/c1.json", "w"))
PY

figure() { "$check" "$1" "$2" | awk -v n="$2" '$1 == n { print $3 }'; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

printf "%-4s %-22s %8s %7s %9s %10s %8s %8s %10s %13s\n" case configuration "run [s]" steps "active" "ms/step" speedup ghosts exchanges "halo MB/step"
for case in b2 b7 c1; do
  base=""
  for config in "1 process, 1 thread" "1 process, 2 threads" "2 ranks, 1 thread each"; do
    : > "$work/times"
    for ((k = 0; k < repeats; ++k)); do
      out="$work/$case-$k"
      rm -rf "$out"
      case "$config" in
        "1 process, 1 thread") OMP_NUM_THREADS=1 "$runout" run "$work/$case.json" --out "$out" --quiet ;;
        "1 process, 2 threads") OMP_NUM_THREADS=2 "$runout" run "$work/$case.json" --out "$out" --quiet ;;
        *) OMP_NUM_THREADS=1 mpirun --oversubscribe -n 2 "$runout" run "$work/$case.json" --out "$out" --quiet ;;
      esac
      figure "$out/run.json" run >> "$work/times"
    done
    run=$(median < "$work/times")
    steps=$(figure "$out/run.json" steps)
    active=$(awk -v a="$(figure "$out/run.json" active_cells_mean)" 'BEGIN { printf "%.0f", a }')
    ms=$(awk -v r="$run" -v s="$steps" 'BEGIN { printf "%.1f", 1000 * r / s }')
    [ -z "$base" ] && base=$ms
    speedup=$(awk -v b="$base" -v m="$ms" 'BEGIN { printf "%.2f", b / m }')
    ghosts="" exch="" mb=""
    if [[ $config == 2* ]]; then
      ghosts=$(awk -v g="$(figure "$out/run.json" ghost_share)" 'BEGIN { printf "%.1f %%", 100 * g }')
      exch=$(awk -v e="$(figure "$out/run.json" exchanges_per_step)" 'BEGIN { printf "%.1f", e }')
      mb=$(awk -v b="$(figure "$out/run.json" halo_bytes_per_step)" 'BEGIN { printf "%.2f", b / 1e6 }')
    fi
    printf "%-4s %-22s %8.2f %7s %9s %10s %8s %8s %10s %13s\n" "$case" "$config" "$run" "$steps" "$active" "$ms" "$speedup" "$ghosts" "$exch" "$mb"
  done
done
