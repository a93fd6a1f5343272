#pragma once
// The protocol version this build speaks (see proto/robin.proto "Version" and
// docs/protocol.md "Versioning"). Peers are compatible when the major versions are equal.

namespace robin::protocol {

inline constexpr unsigned protocol_major = 1;
/// 1.1 adds NeumannSolveRequest (optional, capability "neumann_solve"); 1.2 adds
/// Envelope.run_id (a server refuses the requests of another run than its body's).
inline constexpr unsigned protocol_minor = 2;

}  // namespace robin::protocol
