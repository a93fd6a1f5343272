#pragma once
// The choices of the coupling options as enums, and for each the one table of the text users
// see (case files, command-line flags, checkpoints, summary.json, log lines;
// docs/case-format.md). The core compares enums; only those boundaries convert, through
// to_string, choice_from_text and choice_texts below.

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace robin {

/// [coupling] algorithm (coupling/coupling_scheme.hpp).
enum class CouplingAlgorithm { robin, robin_constant, dirichlet_neumann, neumann_neumann };
/// [coupling] contact_body of "dirichlet-neumann": body 1, body 2 (1-based in the text), or the
/// more compliant one.
enum class ContactBodyChoice { first, second, automatic };
/// [coupling] stopping (coupling/robin_iteration.hpp).
enum class StoppingRule { either_sequence, joint };
/// [coupling] initial_obstacle: the gap (g^alpha_0 = d) or zero.
enum class InitialObstacle { gap, zero };
/// [coupling] acceleration (coupling/acceleration.hpp); iqn_ils: interface quasi-Newton with
/// inverse least squares.
enum class AccelerationMethod { none, aitken, iqn_ils };

/// How IQN-ILS mixes its least-squares point and predicted image (acceleration.hpp, `mixing`).
enum class QuasiNewtonMixing { full, relaxation, aitken };

/// Each choice of `Choice` with its text, in the order the case file's messages list them.
template <typename Choice>
struct ChoiceSpellings;

template <>
struct ChoiceSpellings<CouplingAlgorithm> {
  static constexpr std::array<std::pair<CouplingAlgorithm, std::string_view>, 4> entries{{
      {CouplingAlgorithm::robin, "robin"},
      {CouplingAlgorithm::robin_constant, "robin-constant"},
      {CouplingAlgorithm::dirichlet_neumann, "dirichlet-neumann"},
      {CouplingAlgorithm::neumann_neumann, "neumann-neumann"},
  }};
};

template <>
struct ChoiceSpellings<ContactBodyChoice> {
  static constexpr std::array<std::pair<ContactBodyChoice, std::string_view>, 3> entries{{
      {ContactBodyChoice::first, "1"},
      {ContactBodyChoice::second, "2"},
      {ContactBodyChoice::automatic, "auto"},
  }};
};

template <>
struct ChoiceSpellings<StoppingRule> {
  static constexpr std::array<std::pair<StoppingRule, std::string_view>, 2> entries{{
      {StoppingRule::either_sequence, "either-sequence"},
      {StoppingRule::joint, "joint"},
  }};
};

template <>
struct ChoiceSpellings<InitialObstacle> {
  static constexpr std::array<std::pair<InitialObstacle, std::string_view>, 2> entries{{
      {InitialObstacle::gap, "gap"},
      {InitialObstacle::zero, "zero"},
  }};
};

template <>
struct ChoiceSpellings<AccelerationMethod> {
  static constexpr std::array<std::pair<AccelerationMethod, std::string_view>, 3> entries{{
      {AccelerationMethod::none, "none"},
      {AccelerationMethod::aitken, "aitken"},
      {AccelerationMethod::iqn_ils, "iqn-ils"},
  }};
};

template <>
struct ChoiceSpellings<QuasiNewtonMixing> {
  static constexpr std::array<std::pair<QuasiNewtonMixing, std::string_view>, 3> entries{{
      {QuasiNewtonMixing::full, "full"},
      {QuasiNewtonMixing::relaxation, "relaxation"},
      {QuasiNewtonMixing::aitken, "aitken"},
  }};
};

/// The enums above.
template <typename Choice>
concept OptionChoice = requires {
  ChoiceSpellings<Choice>::entries;
};

/// The text of `choice`, e.g. "robin-constant". Throws std::logic_error for a value outside
/// the enum.
template <OptionChoice Choice>
std::string to_string(Choice choice) {
  for (const auto& [value, text] : ChoiceSpellings<Choice>::entries) {
    if (value == choice) return std::string(text);
  }
  throw std::logic_error("to_string: a coupling option choice outside its enum");
}

/// The choice whose text is `text`; nullopt when none is.
template <OptionChoice Choice>
std::optional<Choice> choice_from_text(std::string_view text) {
  for (const auto& [value, spelling] : ChoiceSpellings<Choice>::entries) {
    if (spelling == text) return value;
  }
  return std::nullopt;
}

/// The texts of every choice, in the order of ChoiceSpellings.
template <OptionChoice Choice>
std::vector<std::string> choice_texts() {
  std::vector<std::string> texts;
  for (const auto& entry : ChoiceSpellings<Choice>::entries) texts.emplace_back(entry.second);
  return texts;
}

}  // namespace robin
