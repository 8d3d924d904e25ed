#!/usr/bin/env bash
# Link-time proof that the real-time core is allocation-free: no object in the given static
# libraries (or object files) may reference heap allocation, exceptions, locks, stdio, blocking
# calls or out-of-line atomics. Exit 0 when clean, 1 with one line per offending reference.
set -euo pipefail

if [ "$#" -eq 0 ] || [ "$1" = "--help" ] || [ "$1" = "-h" ]; then
  echo "usage: $0 LIBRARY.a|OBJECT.o ..." >&2
  echo "Lists every undefined symbol of the given objects that the 1 kHz core must not use." >&2
  exit 2
fi

NM=${NM:-nm}
CXXFILT=${CXXFILT:-c++filt}

# Mangled names of what the cycle must never reach, one extended regex per family.
forbidden=(
  '^(malloc|calloc|realloc|free|aligned_alloc|posix_memalign|memalign|valloc|pvalloc|strdup|strndup|reallocarray)$'  # heap
  '^(mmap|mmap64|munmap|mremap|brk|sbrk)$'                              # heap by another route
  '^_Zn[wa]'                                                            # operator new, new[] (all forms)
  '^_Zd[la]'                                                            # operator delete, delete[] (all forms)
  '^__cxa_(allocate_exception|throw|rethrow|begin_catch|end_catch)$'   # exceptions
  '^(_Unwind_Resume|__gxx_personality_v0)$'                             # exception tables: -fno-exceptions was lost
  '^_ZSt[0-9]+__throw_'                                                 # std::__throw_* (containers that may throw)
  '^__cxa_guard_(acquire|release|abort)$'                               # function-local statics: a hidden lock
  '^__cxa_thread_atexit(_impl)?$'                                       # thread_local with a destructor: allocates
  '^pthread_(mutex|rwlock|cond|spin)_'                                  # locks
  '^_ZNSt(18condition_variable|5mutex|15recursive_mutex|11timed_mutex)'  # std:: locks and waits
  '^(sem_wait|sem_timedwait|sem_post)$'                                 # semaphores
  '^(__)?(printf|fprintf|sprintf|snprintf|vprintf|vfprintf|vsprintf|vsnprintf|dprintf|vdprintf)(_chk)?$'  # stdio
  '^(puts|fputs|putchar|fputc|putc|_IO_putc|fwrite|fread|fopen|fclose|fflush|perror|getc|fgets)(_unlocked)?$'  # stdio
  '^(__overflow|__uflow|__isoc99_v?[fs]?scanf|v?[fs]?scanf)$'            # stdio internals, input
  '^_ZSt(4cout|4cerr|4clog|3cin)$|^_ZNS[oi]|^_ZNSt8ios_base4Init'       # iostreams
  '^__atomic_'                                                          # atomics that are not lock-free
  '^(sleep|usleep|nanosleep|clock_nanosleep|read|write|open|open64|close|poll|ppoll|select|pselect|epoll_wait|ioctl|syscall)$'  # blocking calls
)
pattern=$(IFS='|'; echo "${forbidden[*]}")

status=0
for input in "$@"; do
  if [ ! -f "$input" ]; then
    echo "check-no-alloc: $input: no such file (expected a static library or object file)" >&2
    exit 2
  fi
  # nm must read every member: an unreadable input proves nothing, so it is an error.
  if ! listing=$("$NM" -A -u --format=posix "$input" 2>&1); then
    echo "check-no-alloc: $input: nm could not read it: $listing" >&2
    exit 2
  fi
  # GCC's LTO objects carry bytecode, not the calls that the final code will make.
  if "$NM" -A --format=posix "$input" 2>/dev/null | grep -q ' __gnu_lto_'; then
    echo "check-no-alloc: $input: holds LTO bytecode, which nm cannot check; build the core without -flto" >&2
    exit 2
  fi
  # --format=posix prints "archive[member]: symbol U" (or "object: symbol U").
  while read -r where symbol _; do
    if [[ "$symbol" =~ $pattern ]]; then
      echo "check-no-alloc: ${where%:} references $symbol ($(echo "$symbol" | "$CXXFILT"))"
      status=1
    fi
  done <<<"$listing"
done

if [ "$status" -ne 0 ]; then
  echo "check-no-alloc: FAILED: the real-time core must not allocate, throw, lock, print or block" >&2
fi
exit "$status"
