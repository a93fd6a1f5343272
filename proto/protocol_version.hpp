#pragma once
// The protocol version this build speaks (see proto/robin.proto "Version" and
// docs/protocol.md "Versioning"). Peers are compatible when the major versions are equal.

namespace robin::protocol {

inline constexpr unsigned protocol_major = 1;
/// 1.1 adds NeumannSolveRequest (optional, capability "neumann_solve").
inline constexpr unsigned protocol_minor = 1;

}  // namespace robin::protocol
