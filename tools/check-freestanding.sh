#!/usr/bin/env bash
# Checks that the freestanding core archive references nothing of the hosted runtime: no heap
# (malloc, operator new/delete), no exceptions (__cxa_throw, personality routines), no RTTI
# (typeinfo) and no iostreams. Usage: [NM=arm-none-eabi-nm] check-freestanding.sh ARCHIVE.a
set -euo pipefail
archive=${1:?usage: check-freestanding.sh ARCHIVE}
[ -f "$archive" ] || { echo "check-freestanding: no such archive: $archive" >&2; exit 2; }
undefined=$("${NM:-nm}" -C --undefined-only "$archive" | awk 'NF >= 2 && $1 == "U" { $1 = ""; print substr($0, 2) }' | sort -u)
forbidden='^(malloc|calloc|realloc|free|aligned_alloc|posix_memalign)$|operator new|operator delete|__cxa_throw|__cxa_allocate_exception|__cxa_begin_catch|__gxx_personality|typeinfo|std::ios_base|std::basic_ostream|std::cout|std::cerr|printf|puts|fwrite'
bad=$(grep -E "$forbidden" <<<"$undefined" || true)
if [ -n "$bad" ]; then
  echo "check-freestanding: $archive references hosted runtime symbols:" >&2
  sed 's/^/  /' <<<"$bad" >&2
  exit 1
fi
count=$(grep -c . <<<"$undefined" || true)
echo "check-freestanding: $archive is freestanding ($count undefined symbols, all allowed):"
sed 's/^/  /' <<<"$undefined"
