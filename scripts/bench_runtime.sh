#!/bin/sh
# Run the dcr-runtime query benchmarks (paper Table 1 workloads, Table 3 attenuation rows, heat
# geodesics on a ~5k-vertex surface) and print one median per line. ~2 min on 2 cores.
# Extra arguments go to criterion, e.g. `scripts/bench_runtime.sh modal/dinner`.
# `--features metis` so the heat rows run as a baked base loads (stored METIS surface order).
# Numbers depend on the machine and its load: record both with any result you quote.
set -e
cd "$(dirname "$0")/.."
cargo bench -p dcr-runtime --features metis --bench query -- --warm-up-time 1 --measurement-time 3 "$@" 2>&1 \
    | awk '/time:/ {
               n = ($1 == "time:") ? last : $1
               match($0, /\[[^]]*\]/); split(substr($0, RSTART + 1, RLENGTH - 2), t, " ")
               printf "%-32s median %s %s\n", n, t[3], t[4]; next
           }
           /^[a-z][^ ]*\/[^ ]*$/ { last = $1 }'
