#pragma once
// The protocol version this build speaks (see proto/robin.proto "Version" and
// docs/protocol.md "Versioning"). Peers are compatible when the major versions are equal.

namespace robin::protocol {

inline constexpr unsigned protocol_major = 1;
inline constexpr unsigned protocol_minor = 0;

}  // namespace robin::protocol
