#pragma once
// Error types shared by the numerics. Exceptions are reserved for bad input and
// impossible configurations; solver outcomes (converged, not converged,
// breakdown) are returned as values.

#include <stdexcept>
#include <string>

namespace robin {

/// Bad user input: a file, field, mesh or material that cannot be used.
/// The message names the file, the field (and line when known) and the body.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A body whose stiffness cannot be factorized (rigid motions not removed by its
/// Dirichlet conditions, or a numerically singular matrix). Names the body.
class SingularBodyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A body larger than the limits its solver was given (degrees of freedom, factor memory):
/// refused before the work that would exceed them starts. Names the body, the limit and the
/// option that raises it. An InputError: the request, not the server, is at fault.
class ResourceLimitError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace robin
