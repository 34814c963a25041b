#!/usr/bin/env python3
"""Flash and RAM of a linked image per object file, from its GNU ld link map.

    image-size-by-object.py IMAGE.map [--top N] [--summary]

Counts the input sections placed in the output sections that occupy flash (.vectors, .text,
.ARM.exidx, .init_array, .data's load image) and RAM (.data, .bss), grouped by archive member
or object file; the RECORD region's .record (a compiled-in record) is listed apart."""
import argparse
import collections
import re

FLASH = {".vectors", ".text", ".ARM.exidx", ".init_array", ".data"}
RAM = {".data", ".bss"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("map")
    parser.add_argument("--top", type=int, default=25)
    parser.add_argument("--summary", action="store_true", help="the totals' line only")
    args = parser.parse_args()
    text = open(args.map).read()
    text = text[text.index("Linker script and memory map"):]
    flash, ram, record = collections.Counter(), collections.Counter(), 0
    output = None
    pending = None  # an input section name on its own line; its address and size follow
    for line in text.splitlines():
        m = re.match(r"^(\.\S+)\s", line) or re.match(r"^(\.\S+)$", line)
        if m and not line.startswith(" "):
            output = m.group(1)
            continue
        m = re.match(r"^ (\.\S+|COMMON)\s*$", line)
        if m:
            pending = m.group(1)
            continue
        m = re.match(r"^ (?:(\.\S+|COMMON)\s+)?\s*0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+.*)$", line)
        if not m or (m.group(1) is None and pending is None):
            pending = None
            continue
        pending = None
        size, obj = int(m.group(3), 16), re.sub(r".*/", "", m.group(4).strip())
        if output == ".record":
            record += size
        if output in FLASH:
            flash[obj] += size
        if output in RAM:
            ram[obj] += size
    print("flash %d bytes, RAM (data + bss, without the stack) %d bytes, record %d bytes" % (
        sum(flash.values()), sum(ram.values()), record))
    if args.summary:
        return
    print("flash by object:")
    for obj, size in flash.most_common(args.top):
        print("  %7d  %s" % (size, obj))
    print("RAM by object:")
    for obj, size in ram.most_common(10):
        print("  %7d  %s" % (size, obj))


if __name__ == "__main__":
    main()
