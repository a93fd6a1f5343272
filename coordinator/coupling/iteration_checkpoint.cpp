#include "coupling/iteration_checkpoint.hpp"

#include <algorithm>
#include <utility>

#include "coupling/checkpoint_encoding.hpp"

namespace robin {
namespace {

nlohmann::json body_state_json(const BodyInterfaceState& body) {
  return {{"obstacle", encode_vector(body.obstacle)},
          {"normal_trace", encode_vector(body.normal_trace)},
          {"contact_force", encode_vector(body.contact_force)},
          {"correction", encode_vector(body.correction)}};
}

BodyInterfaceState body_state_from_json(const nlohmann::json& object) {
  return {decode_vector(object, "obstacle"), decode_vector(object, "normal_trace"),
          decode_vector(object, "contact_force"), decode_vector(object, "correction")};
}

nlohmann::json sequence_json(const SequenceResiduals& sequence) {
  return {{"obstacle_change", encode_number(sequence.obstacle_change)},
          {"penetration", encode_number(sequence.penetration)},
          {"complementarity", encode_number(sequence.complementarity)},
          {"force_error", encode_number(sequence.force_error)}};
}

SequenceResiduals sequence_from_json(const nlohmann::json& object) {
  SequenceResiduals sequence;
  sequence.obstacle_change = decode_number(object, "obstacle_change");
  sequence.penetration = decode_number(object, "penetration");
  sequence.complementarity = decode_number(object, "complementarity");
  sequence.force_error = decode_number(object, "force_error");
  return sequence;
}

nlohmann::json record_json(const IterationRecord& record) {
  nlohmann::json sequences = nlohmann::json::array();
  for (const SequenceResiduals& sequence : record.sequences) {
    sequences.push_back(sequence_json(sequence));
  }
  return {{"iteration", record.iteration},
          {"obstacle_change", encode_number(record.obstacle_change)},
          {"obstacle_step", encode_number(record.obstacle_step)},
          {"penetration", encode_number(record.penetration)},
          {"force_balance", encode_number(record.force_balance)},
          {"complementarity", encode_number(record.complementarity)},
          {"correction", encode_number(record.correction)},
          {"active", record.active},
          {"qp_iterations", record.qp_iterations},
          {"seconds", encode_number(record.seconds)},
          {"acceleration_state", record.acceleration_state},
          {"sequences", sequences}};
}

/// One integer per body.
std::vector<int> integers(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& values = member(object, key);
  if (!values.is_array() ||
      !std::all_of(values.begin(), values.end(),
                   [](const nlohmann::json& value) { return value.is_number_integer(); })) {
    throw CheckpointFormatError("the checkpoint's '" + key + "' is not an array of integers");
  }
  std::vector<int> result;
  for (const nlohmann::json& value : values) result.push_back(value.get<int>());
  return result;
}

IterationRecord record_from_json(const nlohmann::json& object) {
  IterationRecord record;
  record.iteration = decode_integer(object, "iteration");
  record.obstacle_change = decode_number(object, "obstacle_change");
  record.obstacle_step = decode_number(object, "obstacle_step");
  record.penetration = decode_number(object, "penetration");
  record.force_balance = decode_number(object, "force_balance");
  record.complementarity = decode_number(object, "complementarity");
  record.correction = decode_number(object, "correction");
  record.active = integers(object, "active");
  record.qp_iterations = integers(object, "qp_iterations");
  record.seconds = decode_number(object, "seconds");
  record.acceleration_state = decode_text(object, "acceleration_state");
  const nlohmann::json& sequences = member(object, "sequences");
  if (!sequences.is_array())
    throw CheckpointFormatError("the checkpoint's 'sequences' is no array");
  for (const nlohmann::json& sequence : sequences) {
    record.sequences.push_back(sequence_from_json(sequence));
  }
  return record;
}

IterationStatus status_from_text(const std::string& text) {
  for (const IterationStatus status : {IterationStatus::converged, IterationStatus::max_iterations,
                                       IterationStatus::diverged, IterationStatus::stagnated}) {
    if (to_string(status) == text) return status;
  }
  throw CheckpointFormatError("the checkpoint's 'status' is '" + text + "'");
}

nlohmann::json force_sequence_json(const ForceSequenceState& sequence) {
  return {{"previous", encode_vector(sequence.previous)},
          {"previous_change", encode_number(sequence.previous_change)},
          {"step", encode_number(sequence.step)}};
}

ForceSequenceState force_sequence_from_json(const nlohmann::json& object) {
  return {decode_vector(object, "previous"), decode_number(object, "previous_change"),
          decode_number(object, "step")};
}

}  // namespace

nlohmann::json to_json(const IterationCheckpoint& checkpoint) {
  nlohmann::json document = {
      {"iteration", checkpoint.iteration},
      {"stopped", checkpoint.stopped},
      {"status", to_string(checkpoint.status)},
      {"message", checkpoint.message},
      {"algorithm", checkpoint.algorithm},
      {"completed_by_sequence", checkpoint.completed_by_sequence},
      {"next_iterate", encode_vector(checkpoint.next_iterate)},
      {"initial_iterate", encode_vector(checkpoint.initial_iterate)},
      {"restart_iterate", encode_vector(checkpoint.restart_iterate)},
      {"acceleration", checkpoint.acceleration},
      {"monitor",
       {{"first_step", encode_number(checkpoint.monitor.first_step)},
        {"smallest_step", encode_number(checkpoint.monitor.smallest_step)},
        {"best_history", encode_numbers(checkpoint.monitor.best_history)}}},
      {"critical_compute_seconds", encode_number(checkpoint.critical_compute_seconds)},
      {"port_seconds", encode_number(checkpoint.port_seconds)},
      {"wall_seconds", encode_number(checkpoint.wall_seconds)}};
  nlohmann::json sequences = nlohmann::json::array();
  for (const ForceSequenceState& sequence : checkpoint.force_sequences) {
    sequences.push_back(force_sequence_json(sequence));
  }
  document["force_sequences"] = sequences;
  nlohmann::json bodies = nlohmann::json::array();
  for (const BodyInterfaceState& body : checkpoint.state.bodies) {
    bodies.push_back(body_state_json(body));
  }
  document["state"] = bodies;
  nlohmann::json history = nlohmann::json::array();
  for (const IterationRecord& record : checkpoint.history) history.push_back(record_json(record));
  document["history"] = history;
  return document;
}

IterationCheckpoint iteration_checkpoint_from_json(const nlohmann::json& document) {
  IterationCheckpoint checkpoint;
  checkpoint.iteration = decode_integer(document, "iteration");
  checkpoint.stopped = decode_flag(document, "stopped");
  checkpoint.status = status_from_text(decode_text(document, "status"));
  checkpoint.message = decode_text(document, "message");
  checkpoint.algorithm = decode_text(document, "algorithm");
  checkpoint.completed_by_sequence = decode_integer(document, "completed_by_sequence");
  checkpoint.next_iterate = decode_vector(document, "next_iterate");
  checkpoint.initial_iterate = decode_vector(document, "initial_iterate");
  checkpoint.restart_iterate = decode_vector(document, "restart_iterate");
  checkpoint.acceleration = member(document, "acceleration");
  const nlohmann::json& monitor = member(document, "monitor");
  checkpoint.monitor.first_step = decode_number(monitor, "first_step");
  checkpoint.monitor.smallest_step = decode_number(monitor, "smallest_step");
  checkpoint.monitor.best_history = decode_numbers(monitor, "best_history");
  const nlohmann::json& sequences = member(document, "force_sequences");
  if (!sequences.is_array()) {
    throw CheckpointFormatError("the checkpoint's 'force_sequences' is no array");
  }
  for (const nlohmann::json& sequence : sequences) {
    checkpoint.force_sequences.push_back(force_sequence_from_json(sequence));
  }
  checkpoint.critical_compute_seconds = decode_number(document, "critical_compute_seconds");
  checkpoint.port_seconds = decode_number(document, "port_seconds");
  checkpoint.wall_seconds = decode_number(document, "wall_seconds");
  const nlohmann::json& state = member(document, "state");
  if (!state.is_array()) throw CheckpointFormatError("the checkpoint's 'state' is no array");
  for (const nlohmann::json& body : state) {
    checkpoint.state.bodies.push_back(body_state_from_json(body));
  }
  const nlohmann::json& history = member(document, "history");
  if (!history.is_array()) throw CheckpointFormatError("the checkpoint's 'history' is no array");
  for (const nlohmann::json& record : history) {
    checkpoint.history.push_back(record_from_json(record));
  }
  if (static_cast<int>(checkpoint.history.size()) != checkpoint.iteration) {
    throw CheckpointFormatError("the checkpoint's 'history' has " +
                                std::to_string(checkpoint.history.size()) +
                                " records for iteration " + std::to_string(checkpoint.iteration));
  }
  return checkpoint;
}

nlohmann::json to_json(const LoadStepCheckpoint& step) {
  return {{"step", step.step},
          {"factor", encode_number(step.factor)},
          {"warm_started", step.warm_started},
          {"seconds", encode_number(step.seconds)},
          {"loop", to_json(step.iteration)}};
}

LoadStepCheckpoint load_step_checkpoint_from_json(const nlohmann::json& document) {
  LoadStepCheckpoint step;
  step.step = decode_integer(document, "step");
  step.factor = decode_number(document, "factor");
  step.warm_started = decode_flag(document, "warm_started");
  step.seconds = decode_number(document, "seconds");
  step.iteration = iteration_checkpoint_from_json(member(document, "loop"));
  if (!step.iteration.stopped) {
    throw CheckpointFormatError("the checkpoint's completed load step " +
                                std::to_string(step.step) + " has a loop that did not stop");
  }
  return step;
}

}  // namespace robin
