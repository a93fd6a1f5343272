#!/usr/bin/python3
"""vtu_compression_benchmark.py FILE.vtu [--repeats N]

The zlib settings of the VTU writer (subdomain/numerics/vtu_writer.cpp) on the arrays of a
written file: reads the appended records of FILE.vtu (binary, vtkZLibDataCompressor, UInt64
headers, as robin-contact writes them), decompresses them, and compresses the same 32 KiB
blocks again with each setting, one fresh deflate stream per block as the writer makes them.
Prints a Markdown table: setting, seconds per pass (best of N, default 3), compressed MB.
Python's zlib module calls the same C library as the writer; the times include Python's
per-block overhead, the same for every setting. Not a test: docs/benchmarks.md reports it.
"""

import argparse
import re
import struct
import sys
import time
import zlib

SETTINGS = (
    ("level 1 (compress2's default strategy)", 1, zlib.Z_DEFAULT_STRATEGY),
    ("level 1, Z_RLE (the writer's)", 1, zlib.Z_RLE),
    ("level 6", 6, zlib.Z_DEFAULT_STRATEGY),
    ("level 1, Huffman only", 1, zlib.Z_HUFFMAN_ONLY),
    ("level 0 (stored)", 0, zlib.Z_DEFAULT_STRATEGY),
)
BLOCK = 32768


def appended_arrays(data):
    """The uncompressed bytes of every appended record of a VTU file's content."""
    marker = data.find(b'<AppendedData encoding="raw">')
    if marker < 0 or b'compressor="vtkZLibDataCompressor"' not in data[:marker]:
        raise ValueError("not a zlib-compressed appended VTU file")
    start = data.index(b"_", marker) + 1
    arrays = []
    for offset in sorted({int(value) for value in re.findall(rb'offset="(\d+)"', data[:marker])}):
        position = start + offset
        blocks, _, _ = struct.unpack_from("<QQQ", data, position)
        sizes = struct.unpack_from("<%dQ" % blocks, data, position + 24)
        position += 24 + 8 * blocks
        chunks = []
        for size in sizes:
            chunks.append(zlib.decompress(data[position:position + size]))
            position += size
        arrays.append(b"".join(chunks))
    return arrays


def compress_all(blocks, level, strategy):
    """Total compressed bytes of `blocks`, each its own zlib stream."""
    total = 0
    for block in blocks:
        stream = zlib.compressobj(level, zlib.DEFLATED, 15, 8, strategy)
        total += len(stream.compress(block)) + len(stream.flush())
    return total


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file")
    parser.add_argument("--repeats", type=int, default=3)
    arguments = parser.parse_args()
    with open(arguments.file, "rb") as stream:
        data = stream.read()
    try:
        arrays = appended_arrays(data)
    except (ValueError, struct.error, zlib.error) as error:
        print("%s: %s" % (arguments.file, error), file=sys.stderr)
        return 1
    blocks = [array[k:k + BLOCK] for array in arrays for k in range(0, len(array), BLOCK)]
    print("%s: %d arrays, %.2f MB uncompressed, file %.2f MB" %
          (arguments.file, len(arrays), sum(len(a) for a in arrays) / 1e6, len(data) / 1e6))
    print()
    print("| setting | seconds (best of %d) | compressed MB |" % arguments.repeats)
    print("|---|---|---|")
    for name, level, strategy in SETTINGS:
        best = float("inf")
        for _ in range(max(1, arguments.repeats)):
            begin = time.perf_counter()
            size = compress_all(blocks, level, strategy)
            best = min(best, time.perf_counter() - begin)
        print("| %s | %.4f | %.2f |" % (name, best, size / 1e6))
    return 0


if __name__ == "__main__":
    sys.exit(main())
