#pragma once
// The stages of setting a body up, reported as they begin (progress displays, heartbeats and
// the stage-by-stage profile).

#include <functional>
#include <optional>
#include <string>

namespace robin {

enum class SetupStage {
  mesh,                // decoding and checking the mesh
  assembly,            // stiffness matrix and load vector
  ordering,            // the fill-reducing ordering and symbolic analysis of the factor
  factorization,       // the numerical Cholesky factorization and K^{-1} f
  interface_operator,  // B, e = B K^{-1} f and (when dense) F = B K^{-1} B'
  fields,              // displacement, stress and reactions of the final state
};

/// "mesh", "assembly", "ordering", "factorization", "interface operator", "fields".
inline std::string to_string(SetupStage stage) {
  switch (stage) {
    case SetupStage::mesh:
      return "mesh";
    case SetupStage::assembly:
      return "assembly";
    case SetupStage::ordering:
      return "ordering";
    case SetupStage::factorization:
      return "factorization";
    case SetupStage::interface_operator:
      return "interface operator";
    case SetupStage::fields:
      return "fields";
  }
  return "unknown";
}

/// The stage named `name` (as to_string gives it); empty for any other text.
inline std::optional<SetupStage> setup_stage_named(const std::string& name) {
  for (SetupStage stage :
       {SetupStage::mesh, SetupStage::assembly, SetupStage::ordering, SetupStage::factorization,
        SetupStage::interface_operator, SetupStage::fields}) {
    if (to_string(stage) == name) return stage;
  }
  return std::nullopt;
}

/// Called when a stage begins; may be called from a worker thread. It may throw to abandon the
/// setup (the server does when the request's client has gone): the setup code is exception
/// safe and the exception propagates to whoever started the setup.
using SetupObserver = std::function<void(SetupStage stage)>;

}  // namespace robin
