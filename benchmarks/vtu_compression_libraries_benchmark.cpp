// vtu_compression_libraries_benchmark FILE.vtu [REPEATS]
//
// zlib, libdeflate and zero_run_deflate on the arrays of a .vtu file written by robin-contact
// (binary, vtkZLibDataCompressor layout, UInt64 headers): reads every appended record, decompresses
// its blocks, and compresses the same 32 KiB blocks again with each setting, block by block as the
// VTU writer does (subdomain/numerics/vtu_writer.cpp). Prints a Markdown table: setting, seconds
// per pass (best of REPEATS, default 3), compressed MB. Not a test: docs/benchmarks.md reports it.

#include <libdeflate.h>
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "numerics/zero_run_deflate.hpp"

namespace {

constexpr std::size_t block_size = 32768;

std::uint64_t word_at(const std::string& data, std::size_t position) {
  if (position + 8 > data.size()) throw std::runtime_error("record header past the end");
  std::uint64_t word = 0;
  std::memcpy(&word, data.data() + position, 8);
  return word;
}

/// An appended record: its DataArray type ("Float64", "Int32", ...) and uncompressed bytes.
struct Array {
  std::string type;
  std::string bytes;
};

/// Every appended record, in the order of their offsets.
std::vector<Array> appended_arrays(const std::string& data) {
  const std::size_t marker = data.find("<AppendedData encoding=\"raw\">");
  if (marker == std::string::npos) throw std::runtime_error("no raw appended data");
  const std::size_t start = data.find('_', marker) + 1;
  const std::string head = data.substr(0, marker);
  std::map<std::uint64_t, std::string> offsets;  // offset -> type
  const std::regex offset_pattern("type=\"([A-Za-z0-9]+)\"[^>]*offset=\"([0-9]+)\"");
  for (auto match = std::sregex_iterator(head.begin(), head.end(), offset_pattern);
       match != std::sregex_iterator(); ++match) {
    offsets[std::stoull((*match)[2].str())] = (*match)[1].str();
  }
  libdeflate_decompressor* decompressor = libdeflate_alloc_decompressor();
  std::vector<Array> arrays;
  for (const auto& [offset, type] : offsets) {
    std::size_t position = start + offset;
    const std::uint64_t blocks = word_at(data, position);
    const std::uint64_t last = word_at(data, position + 16);
    std::size_t compressed = position + 24 + 8 * blocks;
    std::string array;
    for (std::uint64_t block = 0; block < blocks; ++block) {
      const std::uint64_t size = word_at(data, position + 24 + 8 * block);
      const std::size_t expected = (block + 1 == blocks && last != 0) ? last : block_size;
      std::string bytes(expected, '\0');
      if (compressed + size > data.size() ||
          libdeflate_zlib_decompress(decompressor, data.data() + compressed, size, bytes.data(),
                                     expected, nullptr) != LIBDEFLATE_SUCCESS) {
        throw std::runtime_error("a block does not decompress");
      }
      array += bytes;
      compressed += size;
    }
    arrays.push_back({type, std::move(array)});
  }
  libdeflate_free_decompressor(decompressor);
  return arrays;
}

/// Compresses one block of an array of the given type; returns the stream's size.
using BlockCompression =
    std::function<std::size_t(const char*, std::size_t, const std::string& type)>;

/// {best seconds, compressed bytes} of compressing every array block by block.
std::pair<double, std::size_t> measure(const std::vector<Array>& arrays,
                                       const BlockCompression& compress, int repeats) {
  double best = std::numeric_limits<double>::infinity();
  std::size_t total = 0;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    total = 0;
    const auto start = std::chrono::steady_clock::now();
    for (const Array& array : arrays) {
      const std::string& bytes = array.bytes;
      for (std::size_t begin = 0; begin < bytes.size(); begin += block_size) {
        total +=
            compress(bytes.data() + begin, std::min(block_size, bytes.size() - begin), array.type);
      }
    }
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return {best, total};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE.vtu [REPEATS]\n", argv[0]);
    return 2;
  }
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  std::ifstream in(argv[1], std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(in)), {});
  const std::vector<Array> arrays = appended_arrays(data);
  std::size_t raw = 0;
  for (const Array& array : arrays) raw += array.bytes.size();
  std::printf("%s: %zu arrays, %.2f MB uncompressed, file %.2f MB\n\n", argv[1], arrays.size(),
              raw / 1e6, data.size() / 1e6);
  std::printf("| setting | seconds (best of %d) | compressed MB |\n|---|---|---|\n", repeats);
  std::vector<unsigned char> buffer(2 * block_size + 1024);
  for (const auto& [label, level, strategy] :
       {std::tuple{"zlib level 1, Z_RLE (the writer's before libdeflate)", 1, Z_RLE},
        std::tuple{"zlib level 1", 1, Z_DEFAULT_STRATEGY},
        std::tuple{"zlib level 6", 6, Z_DEFAULT_STRATEGY}}) {
    z_stream stream{};
    deflateInit2(&stream, level, Z_DEFLATED, 15, 8, strategy);
    const auto [seconds, bytes] = measure(
        arrays,
        [&](const char* block, std::size_t size, const std::string&) {
          deflateReset(&stream);
          stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(block));
          stream.avail_in = static_cast<uInt>(size);
          stream.next_out = buffer.data();
          stream.avail_out = static_cast<uInt>(buffer.size());
          deflate(&stream, Z_FINISH);
          return static_cast<std::size_t>(stream.total_out);
        },
        repeats);
    deflateEnd(&stream);
    std::printf("| %s | %.4f | %.2f |\n", label, seconds, bytes / 1e6);
  }
  for (const int level : {1, 2, 6}) {
    libdeflate_compressor* compressor = libdeflate_alloc_compressor(level);
    const auto [seconds, bytes] = measure(
        arrays,
        [&](const char* block, std::size_t size, const std::string&) {
          return libdeflate_zlib_compress(compressor, block, size, buffer.data(), buffer.size());
        },
        repeats);
    libdeflate_free_compressor(compressor);
    std::printf("| libdeflate level %d%s | %.4f | %.2f |\n", level,
                level == 1 ? " (the writer's before zero_run_deflate)" : "", seconds, bytes / 1e6);
  }
  libdeflate_compressor* compressor = libdeflate_alloc_compressor(1);
  std::vector<std::uint8_t> stream;
  for (const bool every_array : {true, false}) {
    const auto [seconds, bytes] = measure(
        arrays,
        [&](const char* block, std::size_t size, const std::string& type) {
          if (every_array || type == "Float64") {
            return robin::zero_run_deflate(reinterpret_cast<const std::uint8_t*>(block), size,
                                           stream);
          }
          return libdeflate_zlib_compress(compressor, block, size, buffer.data(), buffer.size());
        },
        repeats);
    std::printf("| %s | %.4f | %.2f |\n",
                every_array ? "zero_run_deflate on every array"
                            : "zero_run_deflate on Float64, libdeflate level 1 on the rest (the "
                              "writer's)",
                seconds, bytes / 1e6);
  }
  libdeflate_free_compressor(compressor);
  return 0;
}
