#!/usr/bin/env bash
# Checks that freestanding code references nothing of the hosted runtime: no heap (malloc,
# _sbrk, operator new/delete), no exceptions (__cxa_throw, personality routines, unwinder), no
# RTTI (typeinfo) and no iostreams or stdio.
#   check-freestanding.sh ARCHIVE.a                 the archive's undefined symbols
#   check-freestanding.sh --image IMAGE.elf [MAP]   every symbol of a linked image (defined or
#                                                   not), and the archive members its link map
#                                                   says were pulled in, and why
# NM selects nm (NM=arm-none-eabi-nm for a cross build). NM_TARGET (e.g. elf32-littlearm) makes
# nm read the objects' own symbol tables as that BFD target, past binutils' LTO plugin: on an LTO
# object (even a fat one) the plugin lists the GIMPLE's symbols, which leave out calls to
# builtins such as malloc and memcpy.
set -euo pipefail
nm_command=("${NM:-nm}")
[ -z "${NM_TARGET:-}" ] || nm_command+=("--target=$NM_TARGET")
forbidden='^(malloc|calloc|realloc|free|aligned_alloc|posix_memalign|_sbrk|_sbrk_r|_malloc_r|_calloc_r|_realloc_r|_free_r)$|operator new|operator delete|__cxa_throw|__cxa_allocate_exception|__cxa_begin_catch|__gxx_personality|_Unwind_|__aeabi_unwind_cpp_pr|typeinfo|std::ios_base|std::basic_ostream|std::cout|std::cerr|printf|(^|[^A-Za-z])f?puts|fwrite'

report_bad() {  # WHAT BAD-SYMBOLS
  echo "check-freestanding: $1 references hosted runtime symbols:" >&2
  sed 's/^/  /' <<<"$2" >&2
  exit 1
}

if [ "${1:-}" = "--image" ]; then
  image=${2:?usage: check-freestanding.sh --image IMAGE.elf [IMAGE.map]}
  map=${3:-}
  [ -f "$image" ] || { echo "check-freestanding: no such image: $image" >&2; exit 2; }
  # "ADDRESS TYPE NAME" or, undefined, "TYPE NAME"; a demangled NAME may hold spaces.
  symbols=$("${nm_command[@]}" -C "$image" | sed -E 's/^ *([0-9a-fA-F]+ )?[A-Za-z?-] //' | sort -u)
  bad=$(grep -E "$forbidden" <<<"$symbols" || true)
  [ -z "$bad" ] || report_bad "$image" "$bad"
  if [ -n "$map" ]; then
    [ -f "$map" ] || { echo "check-freestanding: no such link map: $map" >&2; exit 2; }
    # "Archive member included to satisfy reference by file (symbol)": member, then the
    # referencing file and the symbol in parentheses.
    pulled=$(awk '/^Archive member included/ { on = 1; next } /^(Discarded input sections|Memory Configuration)/ { on = 0 } on' "$map")
    reasons=$(grep -oE '\([^()]+\)$' <<<"$pulled" | tr -d '()' | sort -u || true)
    bad=$(grep -E "$forbidden" <<<"$reasons" || true)
    [ -z "$bad" ] || report_bad "$map (archive members pulled in for)" "$bad"
    members=$(grep -cE '^[^ ].*\.a\(' <<<"$pulled" || true)
    echo "check-freestanding: $map: $members archive members pulled in, none for the heap, exceptions or stdio"
  fi
  echo "check-freestanding: $image is heap-free and exception-free ($(grep -c . <<<"$symbols") symbols)"
  exit 0
fi

archive=${1:?usage: check-freestanding.sh ARCHIVE | --image IMAGE.elf [IMAGE.map]}
[ -f "$archive" ] || { echo "check-freestanding: no such archive: $archive" >&2; exit 2; }
undefined=$("${nm_command[@]}" -C --undefined-only "$archive" | awk 'NF >= 2 && $1 == "U" { $1 = ""; print substr($0, 2) }' | sort -u)
bad=$(grep -E "$forbidden" <<<"$undefined" || true)
[ -z "$bad" ] || report_bad "$archive" "$bad"
count=$(grep -c . <<<"$undefined" || true)
echo "check-freestanding: $archive is freestanding ($count undefined symbols, all allowed):"
sed 's/^/  /' <<<"$undefined"
