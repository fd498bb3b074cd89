#!/bin/bash
# usage: run_queue.sh BINARY NAME... : runs bench/b1_tan37/scen/NAME.json one after the other into runs/NAME
cd "$(dirname "$0")/../.." || exit 1
bin=$1; shift
for n in "$@"; do
  [ -f runs/$n/run.json ] && continue
  /usr/bin/time -f "%e s %M KB" "$bin" run bench/b1_tan37/scen/$n.json --out runs/$n --quiet --force > runs/$n.log 2>&1
  echo "$n $(tail -1 runs/$n.log)" >> runs/queue.log
done
