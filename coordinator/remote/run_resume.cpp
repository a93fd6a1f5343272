#include "remote/run_resume.hpp"

#include <fstream>
#include <iterator>
#include <sstream>

#include "coupling/checkpoint_encoding.hpp"
#include "coupling/result_directory.hpp"

namespace robin {
namespace {

/// The option as the checkpoint records it: a choice (coupling_choices.hpp) by its text, as
/// given on the command line.
template <typename Value>
void add_if_given(nlohmann::json& options, const char* name, const std::optional<Value>& value) {
  if (!value) return;
  if constexpr (OptionChoice<Value>) {
    options[name] = to_string(*value);
  } else {
    options[name] = *value;
  }
}

/// The choice the checkpoint's option `name` gives by its text. Throws CheckpointFormatError
/// when the text is none of the choices.
template <OptionChoice Choice>
Choice checkpointed_choice(const std::string& name, const nlohmann::json& value) {
  const std::string text = value.get<std::string>();
  if (const std::optional<Choice> choice = choice_from_text<Choice>(text)) return *choice;
  std::string choices;
  for (const std::string& choice : choice_texts<Choice>()) {
    choices += (choices.empty() ? "" : ", ") + choice;
  }
  throw CheckpointFormatError("the checkpoint's option " + name + " is '" + text +
                              "', not one of: " + choices);
}

/// Sets the option `name` of `settings` from the checkpoint's JSON value.
void apply_option(CoordinatorSettings& settings, const std::string& name,
                  const nlohmann::json& value) {
  const auto number = [&] { return value.get<double>(); };
  if (name == "--relaxation") settings.relaxation = number();
  if (name == "--relaxation1") settings.relaxation1 = number();
  if (name == "--relaxation2") settings.relaxation2 = number();
  if (name == "--acceleration") {
    settings.acceleration = checkpointed_choice<AccelerationMethod>(name, value);
  }
  if (name == "--algorithm")
    settings.algorithm = checkpointed_choice<CouplingAlgorithm>(name, value);
  if (name == "--alpha") settings.alpha = number();
  if (name == "--contact-body") {
    settings.contact_body = checkpointed_choice<ContactBodyChoice>(name, value);
  }
  if (name == "--stopping") settings.stopping = checkpointed_choice<StoppingRule>(name, value);
  if (name == "--tolerance") settings.tolerance = number();
  if (name == "--max-iterations") settings.max_iterations = value.get<int>();
  if (name == "--initial-obstacle") {
    settings.initial_obstacle = checkpointed_choice<InitialObstacle>(name, value);
  }
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// The differences between the given options and the checkpoint's, one line each; fills the
/// options not given from the checkpoint.
std::vector<std::string> option_differences(CoordinatorSettings& settings,
                                            const RunCheckpoint& checkpoint) {
  std::vector<std::string> lines;
  const nlohmann::json given = computation_options(settings);
  for (const auto& [name, value] : given.items()) {
    if (!checkpoint.options.contains(name)) {
      lines.push_back(name + " " + value.dump() + " (the interrupted run did not give " + name +
                      ")");
    } else if (checkpoint.options.at(name) != value) {
      lines.push_back(name + " " + value.dump() + " (the interrupted run had " +
                      checkpoint.options.at(name).dump() + ")");
    }
  }
  for (const auto& [name, value] : checkpoint.options.items()) {
    if (!given.contains(name)) apply_option(settings, name, value);
  }
  if (!settings.overrides.empty() && settings.overrides != checkpoint.overrides) {
    std::string text = "--set";
    for (const std::string& item : settings.overrides) text += " " + item;
    text += " (the interrupted run had";
    for (const std::string& item : checkpoint.overrides) text += " --set " + item;
    lines.push_back(text + (checkpoint.overrides.empty() ? " none)" : ")"));
  }
  settings.overrides = checkpoint.overrides;
  return lines;
}

std::string case_change(const std::filesystem::path& case_file, const RunCheckpoint& checkpoint) {
  const std::string hash = file_sha256(case_file);
  if (hash == checkpoint.case_sha256) return "";
  std::ostringstream text;
  text << "the case file '" << case_file.string() << "' has changed since the checkpoint (SHA-256 "
       << checkpoint.case_sha256 << " then, " << hash << " now)";
  const std::vector<std::string> keys =
      toml_differences(checkpoint.case_text, read_text(case_file));
  if (!keys.empty()) {
    text << "; changed keys:";
    for (const std::string& key : keys) text << "\n  " << key;
  }
  return text.str();
}

}  // namespace

nlohmann::json computation_options(const CoordinatorSettings& settings) {
  nlohmann::json options = nlohmann::json::object();
  add_if_given(options, "--relaxation", settings.relaxation);
  add_if_given(options, "--relaxation1", settings.relaxation1);
  add_if_given(options, "--relaxation2", settings.relaxation2);
  add_if_given(options, "--acceleration", settings.acceleration);
  add_if_given(options, "--algorithm", settings.algorithm);
  add_if_given(options, "--alpha", settings.alpha);
  add_if_given(options, "--contact-body", settings.contact_body);
  add_if_given(options, "--stopping", settings.stopping);
  add_if_given(options, "--tolerance", settings.tolerance);
  add_if_given(options, "--max-iterations", settings.max_iterations);
  add_if_given(options, "--initial-obstacle", settings.initial_obstacle);
  return options;
}

RunCheckpoint prepare_resume(CoordinatorSettings& settings) {
  RunCheckpoint checkpoint = read_checkpoint(settings.resume_directory);
  if (settings.case_file.empty()) settings.case_file = checkpoint.case_file;
  std::vector<std::string> problems = option_differences(settings, checkpoint);
  if (const std::string change = case_change(settings.case_file, checkpoint); !change.empty()) {
    problems.insert(problems.begin(), change);
  }
  if (problems.empty()) return checkpoint;
  std::ostringstream text;
  text << "cannot resume the run in '" << settings.resume_directory.string()
       << "' (checkpoint after iteration " << checkpoint.iteration.iteration
       << (checkpoint.step > 0 ? " of load step " + std::to_string(checkpoint.step) : "")
       << "): it would not compute the interrupted run:";
  for (const std::string& problem : problems) text << "\n  " << problem;
  text << "\nStart a new run (--output) instead, or resume with the interrupted run's case and "
          "options";
  throw ResumeRefused(text.str());
}

void check_resumable(const CaseDefinition& definition, const RunCheckpoint& checkpoint) {
  const std::size_t steps = definition.loading.factors.size();
  if (definition.loading.stepped()
          ? checkpoint.step >= 1 && static_cast<std::size_t>(checkpoint.step) <= steps
          : checkpoint.step == 0) {
    return;
  }
  throw ResumeRefused(
      "cannot resume a run of '" + definition.file.string() + "': its checkpoint is of " +
      (checkpoint.step == 0 ? std::string("a run without load steps")
                            : "load step " + std::to_string(checkpoint.step)) +
      ", the case has " +
      (steps == 0 ? std::string("no [loading] steps") : std::to_string(steps) + " load steps") +
      "; start a new run instead");
}

}  // namespace robin
