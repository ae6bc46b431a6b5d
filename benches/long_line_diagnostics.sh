#!/bin/sh
# Two plan sets with N diagnostics each (default 100,000): the same plan
# of N rows, each naming an undeclared input, the rows all on one line
# (`one_line/`) or one per line (`per_line/`). `rcsc check` reports each
# name as `unknown_name`, so the two sets differ only in where the
# diagnostics sit; BENCHMARKS.md times `rcsc check` on both.
#
#   benches/long_line_diagnostics.sh OUT [N]
#   /usr/bin/time -v target/release/rcsc check OUT/one_line >/dev/null 2>&1
#   /usr/bin/time -v target/release/rcsc check OUT/per_line >/dev/null 2>&1
set -eu
out=${1:?usage: $0 OUT_DIR [N]}
n=${2:-100000}
for shape in one_line per_line; do
    mkdir -p "$out/$shape"
    if [ "$shape" = one_line ]; then sep=''; else sep='\n'; fi
    awk -v n="$n" -v sep="$sep" 'BEGIN {
        printf "controller A {\n    command GO\n    plan GO {\n        *0 when new_command -> Done\n"
        for (i = 0; i < n; i++) printf " S1 when u%d -> Done%s", i, sep
        printf "\n    }\n}\n"
    }' > "$out/$shape/a.rcs"
done
