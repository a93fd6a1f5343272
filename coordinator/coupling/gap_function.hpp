#pragma once
// The optional analytic initial gap g0(x, y, z), added to the geometric normal gap of each
// contact pair. Parsed by muParser; variables x, y and z (z = 0 on plane bodies), plus user
// constants.
//
// Thread compatibility: evaluation is const but writes the parser's bound variables, so one
// object must not be evaluated from several threads at once (give each thread its own object).

#include <map>
#include <memory>
#include <string>

namespace robin {

class GapFunction {
 public:
  /// Parses `expression` and evaluates it once at (0, 0, 0) so that syntax errors and unknown
  /// names surface here (the value there is not checked). Throws InputError starting with
  /// `context` (e.g. "case.toml:12: gap.expression") and giving the parser's message and
  /// position (0-based character index), also for a constant named x, y or z or not finite.
  GapFunction(const std::string& expression, const std::map<std::string, double>& constants,
              const std::string& context);
  ~GapFunction();
  GapFunction(const GapFunction&) = delete;
  GapFunction& operator=(const GapFunction&) = delete;

  /// Value at (x, y, z) (z = 0 for plane bodies). Throws InputError when the value is not
  /// finite.
  double operator()(double x, double y, double z = 0.0) const;
  const std::string& expression() const { return expression_; }

 private:
  struct Implementation;
  std::unique_ptr<Implementation> implementation_;
  std::string expression_;
  std::string context_;
};

}  // namespace robin
