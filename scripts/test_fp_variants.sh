#!/usr/bin/env bash
# The whole test suite under four compiler settings, each in its own build directory
# (build-fp-<variant>), to prove that no test depends on the last bits of floating-point
# results (docs/robustness.md, "Any CPU, any flags"):
#
#   o2          -O2
#   native      -O3 -march=native            (AVX-512 where the CPU has it)
#   nocontract  -O2 -ffp-contract=off        (no fused multiply-add anywhere)
#   fma         -O2 -mfma -ffp-contract=fast (fused multiply-add wherever the compiler can; GCC's
#                                             ISO C++ mode does not contract by default)
#
#   bash scripts/test_fp_variants.sh [variant...]     (default: all four; fma skipped without FMA)
# Exit 0 when every variant's ctest passes; the summary names each variant's result.
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh || exit 1
declare -A flags=(
  [o2]="-O2"
  [native]="-O3 -march=native"
  [nocontract]="-O2 -ffp-contract=off"
  [fma]="-O2 -mfma -ffp-contract=fast"
)
variants=("$@")
((${#variants[@]})) || variants=(o2 native nocontract fma)
status=0
summary=()
for v in "${variants[@]}"; do
  if [[ -z "${flags[$v]:-}" ]]; then
    echo "unknown variant '$v' (o2, native, nocontract, fma)" >&2
    exit 2
  fi
  if [[ "$v" == fma ]] && ! grep -qw fma /proc/cpuinfo; then
    summary+=("$v: skipped (this CPU has no FMA)")
    continue
  fi
  dir=build-fp-$v
  f="${flags[$v]} -DNDEBUG"
  echo "== $v: $f"
  if BUILD_DIR=$dir bash scripts/build.sh -DCMAKE_CXX_FLAGS_RELEASE="$f" -DCMAKE_C_FLAGS_RELEASE="$f" &&
    (cd "$dir" && ctest --output-on-failure -j"$(nproc)"); then
    summary+=("$v: passed ($f)")
  else
    summary+=("$v: FAILED ($f)")
    status=1
  fi
done
echo
echo "CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
printf '%s\n' "${summary[@]}"
exit $status
