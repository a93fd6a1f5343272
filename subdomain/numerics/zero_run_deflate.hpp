#pragma once
// A zlib stream (RFC 1950 around one RFC 1951 deflate block) for floating-point field data,
// made in one pass at memory speed.
//
// Finite-element fields written as doubles compress little beyond their zero bytes: the
// mantissa bytes of computed values are nearly uniform, while structurally zero components
// (the z of a plane displacement, the out-of-plane shear stresses, contact forces away from the
// contact boundary) are runs of zero bytes. The encoder keeps exactly that: one block with
// deflate's fixed Huffman codes, every byte a literal (8 bits for 0-143, 9 for 144-255), every
// run of at least `minimum_zero_run` zero bytes one literal zero followed by matches at
// distance 1 (lengths 3-258). The output is at most 9/8 of the input plus 8 bytes, and any
// inflate implementation (zlib, libdeflate, VTK's vtkZLibDataCompressor) reads it.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace robin {

/// Shortest run of zero bytes coded as a match: a literal zero and a match of 3 cost 20 bits,
/// four literal zeros 32.
constexpr std::size_t minimum_zero_run = 4;

/// Replaces `stream` by the zlib stream of the `size` bytes at `data`; returns its size.
std::size_t zero_run_deflate(const std::uint8_t* data, std::size_t size,
                             std::vector<std::uint8_t>& stream);

}  // namespace robin
