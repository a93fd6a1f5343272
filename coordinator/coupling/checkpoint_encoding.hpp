#pragma once
// Exact JSON encodings of the numbers of a checkpoint (checkpoint.hpp). A finite double is a
// JSON number written with the shortest digits that read back to the same double (nlohmann's
// dump), so decode(encode(x)) == x bit for bit; NaN and the infinities, which JSON numbers
// cannot hold, are the strings "nan", "inf" and "-inf". A vector is an array of such values.

#include <Eigen/Core>
#include <deque>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace robin {

/// The checkpoint is not one this program wrote or can read; the message names the field.
class CheckpointFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

nlohmann::json encode_number(double value);
nlohmann::json encode_vector(const Eigen::VectorXd& values);
nlohmann::json encode_vectors(const std::deque<Eigen::VectorXd>& columns);
nlohmann::json encode_numbers(const std::vector<double>& values);

/// The member `key` of `object` decoded; throws CheckpointFormatError naming `key` when it is
/// missing or of the wrong type.
double decode_number(const nlohmann::json& object, const std::string& key);
int decode_integer(const nlohmann::json& object, const std::string& key);
bool decode_flag(const nlohmann::json& object, const std::string& key);
std::string decode_text(const nlohmann::json& object, const std::string& key);
Eigen::VectorXd decode_vector(const nlohmann::json& object, const std::string& key);
std::deque<Eigen::VectorXd> decode_vectors(const nlohmann::json& object, const std::string& key);
std::vector<double> decode_numbers(const nlohmann::json& object, const std::string& key);
/// The member `key` (any type); throws CheckpointFormatError naming it when it is missing.
const nlohmann::json& member(const nlohmann::json& object, const std::string& key);

}  // namespace robin
