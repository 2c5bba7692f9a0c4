# Sourced by tools/sanitize and tools/fuzz: how the sanitizers report.
# Every report is fatal (halt_on_error; UBSan is built with
# -fno-sanitize-recover) and prints a symbolised stack. Allocation stacks use
# ASan's default frame-pointer unwinder (the sanitized code keeps frame
# pointers): the slow DWARF unwinder on every malloc cost a quarter of the
# sanitized unit tests' CPU time (docs/robustness.md "Sanitizers").
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=0:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
# Leaks inside third-party libraries that are not ours to fix (each one
# explained in lsan.supp).
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PYROLUME_ROOT/tests/fuzz/lsan.supp:print_suppressions=0}"
