#!/usr/bin/env bash
# One run of every benchmark behind docs/performance.md, one after another
# in a fixed order with fixed settings, each bench's output kept in
# target/figures/<date>/<bench>.txt with the machine's load before and after
# it. The figures in docs/performance.md come from one such run (its date is
# given there), so that their ratios are of one build under one load. The
# peer bench's error-versus-cost plots and their CSV (written to
# target/figures/peer/) are copied into target/figures/<date>/peer/.
#
#   ./benches/figures.sh            # everything (about 20 minutes on 2 cores)
#   ./benches/figures.sh step sleep # only these benches, same settings
set -euo pipefail
cd "$(dirname "$0")/.."

out="target/figures/$(date -u +%Y-%m-%d)"
mkdir -p "$out"
criterion=(--warm-up-time 1 --measurement-time 3)

run() {
    local name=$1
    shift
    {
        echo "# $(date -u +%FT%TZ) load: $(cut -d' ' -f1-3 /proc/loadavg)"
        echo "# cargo bench -p vertebra-benches $*"
        cargo bench -q -p vertebra-benches "$@" 2>&1
        echo "# $(date -u +%FT%TZ) load: $(cut -d' ' -f1-3 /proc/loadavg)"
    } | tee "$out/$name.txt"
}

all=(math_instructions joints_instructions step_instructions single_ragdoll_instructions
    capi_instructions math joints step single_ragdoll sleep collisions mapper capi stages peer)
chosen=("${@:-${all[@]}}")

if printf '%s\n' "${chosen[@]}" | grep -q '_instructions$'; then
    ./benches/install-iai-runner.sh
fi
for name in "${chosen[@]}"; do
    case $name in
    capi_instructions)
        run "$name" --bench "$name"
        # The C layer's own instructions: each wrapper's inclusive count
        # beside the Rust calls it makes.
        for f in target/iai/vertebra-benches/capi_instructions/capi_30/c_frame.*/callgrind.*.out; do
            echo "# $f"
            callgrind_annotate --inclusive=yes "$f" 2>/dev/null | grep -E "(vt_world_step|vt_collisions_update|World::step|find_contacts_into|World::swap_contacts)$" |
                grep -v "^ *[0-9,]* .*\[" | tee -a "$out/$name.txt"
        done ;;
    *_instructions) run "$name" --bench "$name" ;;
    stages) run "$name" --bench stages --features stage-timing ;;
    math | joints | step | single_ragdoll | sleep | collisions | mapper | capi)
        run "$name" --bench "$name" -- "${criterion[@]}" ;;
    peer)
        run "$name" --bench "$name" -- "${criterion[@]}"
        cp -r target/figures/peer "$out/" ;;
    *)
        echo "no bench named $name (one of: ${all[*]})" >&2
        exit 1
        ;;
    esac
done
echo "figures in $out"
