# Sourced by tools/sanitize and tools/fuzz: how the sanitizers report.
# Every report is fatal (halt_on_error; UBSan is built with
# -fno-sanitize-recover) and prints a symbolised stack.
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=0:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
