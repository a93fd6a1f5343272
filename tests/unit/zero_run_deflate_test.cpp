// zero_run_deflate against two independent inflate implementations (zlib's uncompress and
// libdeflate's zlib decompressor): every stream must give back the input exactly, and its size
// must be what its construction promises (9/8 of the bytes at most, zero runs nearly free).
#include "numerics/zero_run_deflate.hpp"

#include <gtest/gtest.h>
#include <libdeflate.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

namespace robin {
namespace {

std::vector<std::uint8_t> inflate_with_zlib(const std::vector<std::uint8_t>& stream,
                                            std::size_t size) {
  std::vector<std::uint8_t> bytes(size + 1);
  uLongf length = static_cast<uLongf>(bytes.size());
  const int status = uncompress(bytes.data(), &length, stream.data(), stream.size());
  EXPECT_EQ(status, Z_OK);
  bytes.resize(length);
  return bytes;
}

std::vector<std::uint8_t> inflate_with_libdeflate(const std::vector<std::uint8_t>& stream,
                                                  std::size_t size) {
  libdeflate_decompressor* decompressor = libdeflate_alloc_decompressor();
  std::vector<std::uint8_t> bytes(size);
  std::size_t length = 0;
  const libdeflate_result result = libdeflate_zlib_decompress(
      decompressor, stream.data(), stream.size(), bytes.data(), bytes.size(), &length);
  libdeflate_free_decompressor(decompressor);
  EXPECT_EQ(result, LIBDEFLATE_SUCCESS);
  bytes.resize(length);
  return bytes;
}

/// Compresses `bytes` and checks both inflaters give them back; returns the stream's size.
std::size_t expect_round_trip(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::uint8_t> stream;
  const std::size_t size = zero_run_deflate(bytes.data(), bytes.size(), stream);
  EXPECT_EQ(size, stream.size());
  EXPECT_EQ(inflate_with_zlib(stream, bytes.size()), bytes);
  EXPECT_EQ(inflate_with_libdeflate(stream, bytes.size()), bytes);
  EXPECT_LE(stream.size(), bytes.size() + bytes.size() / 8 + 8);
  return size;
}

TEST(ZeroRunDeflate, EmptyAndSingleBytesRoundTrip) {
  expect_round_trip({});
  expect_round_trip({0});
  expect_round_trip({255});
  expect_round_trip({0, 0, 0});
  expect_round_trip({143, 144, 0, 0, 0, 0, 7});
}

TEST(ZeroRunDeflate, ZeroRunsOfEveryLengthRoundTrip) {
  // runs 1 to 800 (across the match lengths 3-258, their extra bits and the remainders after a
  // full 258) between random bytes, and a stream that begins and ends with a run
  std::mt19937 generator(7);
  std::uniform_int_distribution<int> byte(1, 255);
  std::vector<std::uint8_t> bytes;
  for (std::size_t run = 1; run <= 800; ++run) {
    bytes.insert(bytes.end(), run, 0);
    bytes.push_back(static_cast<std::uint8_t>(byte(generator)));
  }
  bytes.insert(bytes.end(), 1000, 0);
  expect_round_trip(bytes);
  for (std::size_t run = 1; run <= 600; ++run) {
    std::vector<std::uint8_t> only_zeros(run, 0);
    expect_round_trip(only_zeros);
  }
}

TEST(ZeroRunDeflate, RandomBytesExpandByAtMostAnEighth) {
  std::mt19937 generator(11);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::uint8_t> bytes(32768);
  for (std::uint8_t& value : bytes) value = static_cast<std::uint8_t>(byte(generator));
  const std::size_t size = expect_round_trip(bytes);
  // 8 bits for 144 of the 256 values, 9 for 112: 8.44 bits per byte on average
  EXPECT_GT(size, bytes.size());
  EXPECT_LT(static_cast<double>(size) / static_cast<double>(bytes.size()), 1.07);
}

TEST(ZeroRunDeflate, PlaneStressTensorsShrinkByTheirZeroComponents) {
  // 6 doubles per tensor, the last two (yz, xz) zero: 32 bytes of literals (8.44 bits each) and
  // a 16-byte run (literal zero, match of 15: 8 + 7 + 1 + 5 bits) per tensor
  std::mt19937 generator(13);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  std::vector<double> tensors;
  for (int k = 0; k < 4096; ++k) {
    for (int c = 0; c < 4; ++c) tensors.push_back(value(generator));
    tensors.push_back(0.0);
    tensors.push_back(0.0);
  }
  std::vector<std::uint8_t> bytes(tensors.size() * sizeof(double));
  std::memcpy(bytes.data(), tensors.data(), bytes.size());
  const double ratio =
      static_cast<double>(expect_round_trip(bytes)) / static_cast<double>(bytes.size());
  const double expected = (32 * 8.44 + 21) / (48 * 8);
  EXPECT_NEAR(ratio, expected, 0.02);
}

}  // namespace
}  // namespace robin
