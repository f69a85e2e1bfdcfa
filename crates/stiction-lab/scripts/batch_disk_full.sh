#!/usr/bin/env bash
# A full disk, for real: `stiction batch --reports` into a small tmpfs (2 MB by default) until it
# is full, then the space freed (the tmpfs remounted larger) and the same command run with
# --resume. Checks what issue 17 asks: a clear error naming the file and exit 2, no temporary
# file left behind, and after --resume the summary of an undisturbed run (timing aside).
#
# Opt-in, needs root (mount) and python3 (to compare the summaries):
#     cargo build --release && sudo crates/stiction-lab/scripts/batch_disk_full.sh [LOOPS] [SIZE]
# LOOPS defaults to 168 (8 simulated loops copied 21 times), SIZE to 2m. STICTION names the
# binary (default target/release/stiction).
set -euo pipefail
BIN=$(realpath "${STICTION:-target/release/stiction}")
N=${1:-168}
SIZE=${2:-2m}
work=$(mktemp -d)
mnt=$work/disk
cleanup() {
    umount "$mnt" 2>/dev/null || true
    rm -rf "$work"
}
trap cleanup EXIT
mkdir -p "$work/src" "$work/plant" "$mnt"

for k in 0 1 2 3 4 5 6 7; do
    d=$((k % 2 == 0 ? 2 : 0))
    "$BIN" simulate --loop closed --model stenman --param "d=$d" --samples 1500 \
        --noise 0.05 --seed "$((k + 1))" -o "$work/src/$k.csv" 2>/dev/null
done
for i in $(seq 1 "$N"); do
    cp "$work/src/$((i % 8)).csv" "$work/plant/loop$(printf %03d "$i").csv"
done
args=(--sp sp --no-quantify --reports)
status() { "$@" >/dev/null 2>"$work/err" && echo 0 || echo $?; }

code=$(status "$BIN" batch "$work/plant" -o "$work/reference" "${args[@]}")
echo "undisturbed run: exit $code"

mount -t tmpfs -o "size=$SIZE" tmpfs "$mnt"
code=$(status "$BIN" batch "$work/plant" -o "$mnt/out" "${args[@]}")
echo "into a $SIZE file system: exit $code"
sed 's/^/  /' "$work/err"
count() { find "$mnt/out" -name "$1" 2>/dev/null | wc -l; }
temps() { find "$mnt/out" \( -name '.stiction-tmp.*' -o -name '*.tmp[0-9]*' \) | wc -l; }
echo "  loop files $(count '*.json' | tr -d ' ') (with summary.json), reports $(count '*.html' | tr -d ' '), temporary files $(temps | tr -d ' ')"

mount -o remount,size=512m "$mnt"
code=$(status "$BIN" batch "$work/plant" -o "$mnt/out" "${args[@]}" --resume)
echo "space freed, --resume: exit $code, temporary files $(temps | tr -d ' ')"

python3 - "$work/reference/summary.csv" "$mnt/out/summary.csv" <<'PY'
import csv, sys
def rows(path):
    out = []
    for r in csv.DictReader(open(path, newline="")):
        r.pop("seconds")
        out.append(r)
    return out
a, b = rows(sys.argv[1]), rows(sys.argv[2])
same = a == b
print(f"summary after --resume: {len(b)} rows, {'the same as' if same else 'DIFFERENT from'} the undisturbed run's (timing aside)")
sys.exit(0 if same else 1)
PY
