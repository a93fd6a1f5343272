#include "coupling/checkpoint_encoding.hpp"

#include <cmath>
#include <limits>

namespace robin {
namespace {

double number_of(const nlohmann::json& value, const std::string& key) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (text == "inf") return std::numeric_limits<double>::infinity();
    if (text == "-inf") return -std::numeric_limits<double>::infinity();
  }
  throw CheckpointFormatError("the checkpoint's '" + key + "' holds '" + value.dump() +
                              "', not a number");
}

Eigen::VectorXd vector_of(const nlohmann::json& values, const std::string& key) {
  if (!values.is_array()) {
    throw CheckpointFormatError("the checkpoint's '" + key + "' is not an array of numbers");
  }
  Eigen::VectorXd vector(static_cast<Eigen::Index>(values.size()));
  for (std::size_t index = 0; index < values.size(); ++index) {
    vector[static_cast<Eigen::Index>(index)] = number_of(values[index], key);
  }
  return vector;
}

}  // namespace

nlohmann::json encode_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

nlohmann::json encode_vector(const Eigen::VectorXd& values) {
  nlohmann::json array = nlohmann::json::array();
  for (Eigen::Index index = 0; index < values.size(); ++index) {
    array.push_back(encode_number(values[index]));
  }
  return array;
}

nlohmann::json encode_vectors(const std::deque<Eigen::VectorXd>& columns) {
  nlohmann::json array = nlohmann::json::array();
  for (const Eigen::VectorXd& column : columns) array.push_back(encode_vector(column));
  return array;
}

nlohmann::json encode_numbers(const std::vector<double>& values) {
  nlohmann::json array = nlohmann::json::array();
  for (const double value : values) array.push_back(encode_number(value));
  return array;
}

const nlohmann::json& member(const nlohmann::json& object, const std::string& key) {
  if (!object.is_object() || !object.contains(key)) {
    throw CheckpointFormatError("the checkpoint has no '" + key + "'");
  }
  return object.at(key);
}

double decode_number(const nlohmann::json& object, const std::string& key) {
  return number_of(member(object, key), key);
}

int decode_integer(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& value = member(object, key);
  if (!value.is_number_integer()) {
    throw CheckpointFormatError("the checkpoint's '" + key + "' is not an integer");
  }
  return value.get<int>();
}

bool decode_flag(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& value = member(object, key);
  if (!value.is_boolean()) {
    throw CheckpointFormatError("the checkpoint's '" + key + "' is not true or false");
  }
  return value.get<bool>();
}

std::string decode_text(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& value = member(object, key);
  if (!value.is_string()) {
    throw CheckpointFormatError("the checkpoint's '" + key + "' is not a string");
  }
  return value.get<std::string>();
}

Eigen::VectorXd decode_vector(const nlohmann::json& object, const std::string& key) {
  return vector_of(member(object, key), key);
}

std::deque<Eigen::VectorXd> decode_vectors(const nlohmann::json& object, const std::string& key) {
  const nlohmann::json& columns = member(object, key);
  if (!columns.is_array()) {
    throw CheckpointFormatError("the checkpoint's '" + key + "' is not an array of vectors");
  }
  std::deque<Eigen::VectorXd> vectors;
  for (const nlohmann::json& column : columns) vectors.push_back(vector_of(column, key));
  return vectors;
}

std::vector<double> decode_numbers(const nlohmann::json& object, const std::string& key) {
  const Eigen::VectorXd vector = decode_vector(object, key);
  return {vector.data(), vector.data() + vector.size()};
}

}  // namespace robin
