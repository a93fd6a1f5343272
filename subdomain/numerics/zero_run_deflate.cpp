#include "numerics/zero_run_deflate.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

namespace robin {
namespace {

/// A Huffman code as deflate writes it: `bits` bits, first bit of the code in the lowest bit.
struct Code {
  std::uint32_t value = 0;
  int bits = 0;
};

/// `code` of `bits` bits (most significant first, as RFC 1951 3.1.1 defines codes) with its bit
/// order reversed, for the least-significant-first bit packing.
Code reversed(std::uint32_t code, int bits) {
  std::uint32_t value = 0;
  for (int k = 0; k < bits; ++k) value |= ((code >> k) & 1u) << (bits - 1 - k);
  return {value, bits};
}

/// The fixed literal/length codes (RFC 1951 3.2.6) of symbols 0-287.
std::array<Code, 288> fixed_literal_codes() {
  std::array<Code, 288> codes{};
  for (std::uint32_t symbol = 0; symbol < 288; ++symbol) {
    if (symbol < 144) {
      codes[symbol] = reversed(0x30 + symbol, 8);
    } else if (symbol < 256) {
      codes[symbol] = reversed(0x190 + symbol - 144, 9);
    } else if (symbol < 280) {
      codes[symbol] = reversed(symbol - 256, 7);
    } else {
      codes[symbol] = reversed(0xC0 + symbol - 280, 8);
    }
  }
  return codes;
}

/// A match length's symbol, extra bits and their value (RFC 1951 3.2.5), lengths 3-258.
struct LengthCode {
  std::uint32_t symbol = 0;
  int extra_bits = 0;
  std::uint32_t extra = 0;
};

std::array<LengthCode, 259> length_codes() {
  static constexpr std::array<int, 29> base = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                               15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                               67, 83, 99, 115, 131, 163, 195, 227, 258};
  static constexpr std::array<int, 29> extra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                                2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
  std::array<LengthCode, 259> codes{};
  for (int length = 3; length <= 258; ++length) {
    int k = 28;
    while (base[k] > length) --k;
    codes[length] = {static_cast<std::uint32_t>(257 + k), extra[k],
                     static_cast<std::uint32_t>(length - base[k])};
  }
  return codes;
}

/// Bits packed least significant first into a buffer sized for the whole stream beforehand, with
/// 8 bytes to spare after it (flush stores 8 bytes at a time).
class BitWriter {
 public:
  explicit BitWriter(std::uint8_t* out) : out_(out) {}

  /// Adds `bits` bits without flushing: at most 56 bits between two flushes.
  void add(std::uint32_t value, int bits) {
    buffer_ |= static_cast<std::uint64_t>(value) << count_;
    count_ += bits;
  }
  void add(const Code& code) { add(code.value, code.bits); }
  /// Stores the whole bytes of the buffer (little-endian), keeping at most 7 bits.
  void flush() {
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(out_, &buffer_, sizeof buffer_);
    } else {
      for (int k = 0; k < 8; ++k) out_[k] = static_cast<std::uint8_t>(buffer_ >> (8 * k));
    }
    const int whole = count_ & ~7;
    out_ += whole / 8;
    buffer_ = whole == 64 ? 0 : buffer_ >> whole;
    count_ -= whole;
  }
  void write(std::uint32_t value, int bits) {
    add(value, bits);
    flush();
  }
  void write(const Code& code) { write(code.value, code.bits); }
  /// Writes the bits left, the last byte padded with zero bits; returns the end of the output.
  std::uint8_t* finish() {
    for (; count_ > 0; count_ -= 8) {
      *out_++ = static_cast<std::uint8_t>(buffer_);
      buffer_ >>= 8;
    }
    count_ = 0;
    return out_;
  }

 private:
  std::uint8_t* out_;
  std::uint64_t buffer_ = 0;
  int count_ = 0;
};

/// Codes a run of `length` zero bytes that follows a zero byte: matches at distance 1 (the
/// distance code 0, five zero bits), a remainder of one or two as literal zeros.
void write_zero_matches(std::size_t length, BitWriter& writer, const std::array<Code, 288>& codes,
                        const std::array<LengthCode, 259>& lengths) {
  while (length >= 3) {
    // a remainder of 1 or 2 after a full match would need literals: leave 3 or more instead
    std::size_t match = std::min<std::size_t>(length, 258);
    if (length > 258 && length - 258 < 3) match = length - 3;
    const LengthCode& code = lengths[match];
    writer.write(codes[code.symbol]);
    if (code.extra_bits > 0) writer.write(code.extra, code.extra_bits);
    writer.write(0, 5);
    length -= match;
  }
  for (; length > 0; --length) writer.write(codes[0]);
}

}  // namespace

std::size_t zero_run_deflate(const std::uint8_t* data, std::size_t size,
                             std::vector<std::uint8_t>& stream) {
  static const std::array<Code, 288> codes = fixed_literal_codes();
  static const std::array<LengthCode, 259> lengths = length_codes();
  // at most 9 bits per byte, 3 bits of block header and 7 of end of block, 2 + 4 framing bytes,
  // 8 bytes for the writer's last store
  stream.resize(size + size / 8 + 24);
  // zlib header: deflate with a 32 KiB window (0x78), fastest-level flag, FCHECK (RFC 1950)
  stream[0] = 0x78;
  stream[1] = 0x01;
  BitWriter writer(stream.data() + 2);
  writer.write(1, 1);  // BFINAL: the only block
  writer.write(1, 2);  // BTYPE 01: fixed Huffman codes
  std::size_t position = 0;
  while (position < size) {
    // the literals up to the next zero byte, six (at most 54 bits) per flush
    const void* zero = std::memchr(data + position, 0, size - position);
    const std::size_t stretch_end =
        zero == nullptr ? size
                        : static_cast<std::size_t>(static_cast<const std::uint8_t*>(zero) - data);
    for (; position + 6 <= stretch_end; position += 6) {
      for (std::size_t k = 0; k < 6; ++k) writer.add(codes[data[position + k]]);
      writer.flush();
    }
    for (; position < stretch_end; ++position) writer.add(codes[data[position]]);
    writer.flush();
    if (position == size) break;
    std::size_t end = position + 1;
    while (end < size && data[end] == 0) ++end;
    const std::size_t run = end - position;
    if (run >= minimum_zero_run) {
      writer.write(codes[0]);
      write_zero_matches(run - 1, writer, codes, lengths);
    } else {
      for (std::size_t k = 0; k < run; ++k) writer.write(codes[0]);
    }
    position = end;
  }
  writer.write(codes[256]);  // end of block
  std::uint8_t* end = writer.finish();
  const std::uint32_t checksum = libdeflate_adler32(1, data, size);
  for (int shift = 24; shift >= 0; shift -= 8)
    *end++ = static_cast<std::uint8_t>(checksum >> shift);
  stream.resize(static_cast<std::size_t>(end - stream.data()));
  return stream.size();
}

}  // namespace robin
