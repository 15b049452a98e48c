#!/usr/bin/env bash
# Build rigidfem's C++ core with AddressSanitizer + UndefinedBehaviorSanitizer and run the
# tests (and the fuzz corpus replay) against it.
#
#   scripts/sanitize.sh                                   # the whole suite, then the fuzz corpus replay
#   scripts/sanitize.sh tests/test_reliability.py         # only these pytest arguments (no replay)
#   scripts/sanitize.sh tests/test_integrators.py -k newmark -x
#
# What it does:
#   1. A virtual environment of its own, build/sanitize/venv (RIGIDFEM_SANITIZE_VENV to move it),
#      with the build requirements (pyproject.toml, plus cmake and ninja) and the test extras.
#   2. An editable install built with -DRIGIDFEM_SANITIZE=ON (CMakeLists.txt:
#      -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined) and
#      build type RelWithDebInfo (-O2 -g: no LTO, not stripped, so reports name file:line), in
#      its own kept build folder build/sanitize/{wheel_tag}: a second run recompiles only what
#      changed.
#   3. pytest "$@" (default: the whole suite), then, on a full run and when scripts/fuzz.py and
#      tests/fuzz_corpus exist, `python scripts/fuzz.py --replay tests/fuzz_corpus`, with
#      - LD_PRELOAD: the ASan runtime and libstdc++ (CPython itself is not instrumented);
#      - ASAN_OPTIONS=detect_leaks=0 (CPython leaks by design at exit), allocator_may_return_null=1
#        (a runaway allocation throws std::bad_alloc as without ASan instead of ending the process);
#      - UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 and the suppressions of scripts/ubsan.supp
#        (reports inside Eigen that are not ours: each entry says why);
#      - PYTHONMALLOC=malloc: Python's objects come from the instrumented malloc too;
#      - FUZZ_MEMORY_LIMIT=-1: the fuzz workers' address-space limit (RLIMIT_AS) would leave ASan
#        no room for its shadow memory ("ERROR: Failed to mmap");
#      - RIGIDFEM_CONTRACT_TIMEOUT=120 (unless set): the contract test's per-case hang limit, 15 s
#        by default, is too short for the instrumented build (a case of 0.4 s took over 15 s);
#      - Hypothesis without deadlines or too-slow health checks (everything runs 2-3x slower).
#   4. A summary: ASan's reports (build/sanitize/reports/asan.<pid>) and UBSan's "runtime error"
#      lines in the whole output (build/sanitize/output.log).
#
# Exit status: 0 no sanitizer report and the tests (and replay) pass; 1 a sanitizer report;
# 2 no sanitizer report but failed tests or replay cases (the replay fails while the corpus
# holds open cases; timing-sensitive tests may fail only because everything is slower).
# A report inside a fuzz worker shows as a "crash" of tests/test_contract.py with the end of the
# worker's stderr; rerun its reproducer with this script's environment to see it whole.
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
venv="${RIGIDFEM_SANITIZE_VENV:-$root/build/sanitize/venv}"
reports="$root/build/sanitize/reports"
python="${PYTHON:-python3}"
stamp() { date +%s; }
t_start=$(stamp)

echo "== sanitize: environment $venv"
if [[ ! -x "$venv/bin/python" ]]; then
  "$python" -m venv "$venv"
fi
# shellcheck disable=SC1091
source "$venv/bin/activate"
python -m pip install -q --disable-pip-version-check scikit-build-core
# The build requirements of pyproject.toml (plus cmake and ninja): the build below is not isolated.
python -m scikit_build_core.build requires \
  | python -c 'import json, subprocess, sys; subprocess.check_call([sys.executable, "-m", "pip", "install", "-q", "--disable-pip-version-check", *json.load(sys.stdin)])'

echo "== sanitize: build (ASan + UBSan, RelWithDebInfo; the portable core only) in build/sanitize/"
python -m pip install -q --disable-pip-version-check --no-build-isolation -e ".[test]" \
  -Ccmake.define.RIGIDFEM_SANITIZE=ON -Ccmake.define.RIGIDFEM_X86_64_V3=OFF \
  -Ccmake.build-type=RelWithDebInfo \
  "-Cbuild-dir=build/sanitize/{wheel_tag}"
t_built=$(stamp)

# (Not located by importing rigidfem: without the preloaded runtime that import aborts.)
module="$(ls build/sanitize/*/targets/_core*.so | head -n 1)"
# The ASan runtime the module was linked against (GCC links libasan.so.N), else the compiler's.
asan_lib="$(ldd "$module" | awk '/libasan\.so/ {print $3; exit}')"
if [[ -z "$asan_lib" ]]; then
  cxx="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' build/sanitize/*/CMakeCache.txt | head -n 1)"
  asan_lib="$("${cxx:-c++}" -print-file-name=libasan.so)"
fi
if [[ ! -e "$asan_lib" ]]; then
  echo "sanitize: no ASan runtime found (ldd $module)" >&2
  exit 1
fi

# libstdc++ right after it: python does not link it, and ASan's __cxa_throw interceptor finds
# the real __cxa_throw only in libraries loaded at start-up (else the first C++ exception
# stops the process: "CHECK failed: asan_interceptors.cpp ... real___cxa_throw").
preload="$asan_lib"
cxx_lib="$(ldd "$module" | awk '/libstdc\+\+\.so/ {print $3; exit}')"
if [[ -n "$cxx_lib" ]]; then
  preload="$preload $cxx_lib"
fi

rm -rf "$reports"
mkdir -p "$reports"
cat > "$root/build/sanitize/rigidfem_sanitize_profile.py" <<'PY'
from hypothesis import HealthCheck, settings

settings.register_profile("sanitize", deadline=None, suppress_health_check=list(HealthCheck))
settings.load_profile("sanitize")
PY
sanitized=(env
  "LD_PRELOAD=$preload${LD_PRELOAD:+ $LD_PRELOAD}"
  "ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1:log_path=$reports/asan${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
  "UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:suppressions=$root/scripts/ubsan.supp${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
  "PYTHONMALLOC=malloc"
  "FUZZ_MEMORY_LIMIT=-1"
  "RIGIDFEM_CONTRACT_TIMEOUT=${RIGIDFEM_CONTRACT_TIMEOUT:-120}")

log="$root/build/sanitize/output.log"
: > "$log"
# Runs a command with its output (stdout and stderr) also appended to $log: UBSan ignores
# log_path in this set-up (GCC's libubsan next to libasan), so its reports are found there.
run_logged() {
  "$@" 2>&1 | tee -a "$log"
  return "${PIPESTATUS[0]}"
}

failed=0
echo "== sanitize: pytest ${*:-(whole suite)}"
# --capture=sys: a report written to file descriptor 2 by a process that then stops would be
# lost in pytest's fd capture.
run_logged env PYTHONPATH="$root/build/sanitize${PYTHONPATH:+:$PYTHONPATH}" \
  "${sanitized[@]}" python -m pytest -p no:cacheprovider -p rigidfem_sanitize_profile --capture=sys "$@" \
  || failed=1
t_tests=$(stamp)

t_replay=$t_tests
if [[ $# -eq 0 ]]; then
  if [[ -f scripts/fuzz.py && -d tests/fuzz_corpus ]]; then
    echo "== sanitize: fuzz corpus replay"
    run_logged "${sanitized[@]}" python scripts/fuzz.py --replay tests/fuzz_corpus --timeout 120 || failed=1
  else
    echo "== sanitize: no scripts/fuzz.py or tests/fuzz_corpus: replay skipped"
  fi
  t_replay=$(stamp)
fi

echo "== sanitize: durations: build $((t_built - t_start)) s, pytest $((t_tests - t_built)) s, replay $((t_replay - t_tests)) s"
# ASan errors (log files; a file with only a warning such as "failed to allocate" is no error)
# and UBSan's "runtime error" lines in the output. A report in a fuzz worker shows up as a
# "crash" of the contract test with the end of the worker's stderr.
asan_files=()
while IFS= read -r f; do asan_files+=("$f"); done < <(grep -l "ERROR: AddressSanitizer" "$reports"/* 2>/dev/null || true)
ubsan_count=$(grep -c "runtime error:" "$log" || true)
if (( ${#asan_files[@]} + ubsan_count )); then
  echo "== sanitize: ${#asan_files[@]} ASan report(s), $ubsan_count UBSan report(s)"
  for f in "${asan_files[@]}"; do
    echo "---- $f"
    # The error line, the stack frames in rigidfem's sources and the summary.
    grep -E "ERROR|SUMMARY|#[0-9]+ .*(cpp/|rigidfem)" "$f" | head -n 40 || true
  done
  if (( ubsan_count )); then
    echo "---- UBSan, from $log"
    grep -A 3 "runtime error:" "$log" | head -n 80 || true
  fi
  exit 1
fi
echo "== sanitize: no sanitizer reports (output in $log)"
exit $((failed ? 2 : 0))
