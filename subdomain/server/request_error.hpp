#pragma once
// A request the server refuses, with the protocol error code of the reply (internal to the
// server library). Bad body definitions use robin::InputError (BAD_INPUT) instead.

#include <stdexcept>
#include <string>

#include "robin.pb.h"

namespace robin {

class RequestError : public std::runtime_error {
 public:
  RequestError(protocol::ErrorCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  protocol::ErrorCode code() const { return code_; }

 private:
  protocol::ErrorCode code_;
};

}  // namespace robin
