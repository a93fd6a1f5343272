#include "coupling/gap_function.hpp"

#include <muParser.h>

#include <cmath>
#include <sstream>

#include "numerics/errors.hpp"

namespace robin {

// muParser binds variables by address and compiles the expression on the first Eval, which is
// why evaluation mutates the parser: the object is thread-compatible (const methods may not run
// concurrently on one object), not thread-safe.
struct GapFunction::Implementation {
  mu::Parser parser;
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

namespace {

std::string describe_parser_error(const mu::Parser::exception_type& error,
                                  const std::string& expression) {
  std::ostringstream message;
  message << error.GetMsg();
  if (error.GetMsg().find("position") != std::string::npos) {
    message << " (in '" << expression << "')";
  } else if (error.GetPos() >= 0) {
    message << " (position " << error.GetPos() << " of '" << expression << "'";
    if (!error.GetToken().empty()) message << ", token '" << error.GetToken() << "'";
    message << ")";
  } else {
    message << " (expression '" << expression << "')";
  }
  return message.str();
}

void define_constants(mu::Parser& parser, const std::map<std::string, double>& constants,
                      const std::string& context) {
  for (const auto& [name, value] : constants) {
    if (name == "x" || name == "y" || name == "z") {
      throw InputError(context + ": constant '" + name +
                       "' would hide the variable of the same name; choose another name");
    }
    if (!std::isfinite(value)) {
      throw InputError(context + ": constant '" + name + "' is not a finite number");
    }
    try {
      parser.DefineConst(name, value);
    } catch (const mu::Parser::exception_type& error) {
      throw InputError(context + ": constant '" + name + "': " + error.GetMsg());
    }
  }
}

}  // namespace

GapFunction::GapFunction(const std::string& expression,
                         const std::map<std::string, double>& constants, const std::string& context)
    : implementation_(std::make_unique<Implementation>()),
      expression_(expression),
      context_(context) {
  mu::Parser& parser = implementation_->parser;
  define_constants(parser, constants, context_);
  try {
    parser.DefineVar("x", &implementation_->x);
    parser.DefineVar("y", &implementation_->y);
    parser.DefineVar("z", &implementation_->z);
    parser.SetExpr(expression_);
    // muParser reports syntax errors and unknown names only when it compiles the expression,
    // on the first Eval; the value at (0, 0, 0) itself is not checked here.
    static_cast<void>(parser.Eval());
  } catch (const mu::Parser::exception_type& error) {
    throw InputError(context_ + ": " + describe_parser_error(error, expression_));
  }
}

GapFunction::~GapFunction() = default;

double GapFunction::operator()(double x, double y, double z) const {
  implementation_->x = x;
  implementation_->y = y;
  implementation_->z = z;
  double value = 0.0;
  try {
    value = implementation_->parser.Eval();
  } catch (const mu::Parser::exception_type& error) {
    throw InputError(context_ + ": " + describe_parser_error(error, expression_));
  }
  if (!std::isfinite(value)) {
    std::ostringstream message;
    message.precision(17);
    message << context_ << ": '" << expression_ << "' is not finite at (x, y, z) = (" << x << ", "
            << y << ", " << z << "): " << value;
    throw InputError(message.str());
  }
  return value;
}

}  // namespace robin
