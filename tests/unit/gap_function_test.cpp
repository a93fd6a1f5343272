// GapFunction: values against hand computation, constants, and the error messages.

#include "coupling/gap_function.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "numerics/errors.hpp"

namespace robin {
namespace {

const std::string context = "case.toml:5: gap.expression";

/// The message of the InputError thrown by `action`, or "" when nothing is thrown.
template <typename Action>
std::string error_message(Action action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(GapFunction, ParabolaMatchesHandComputedValues) {
  const GapFunction gap("x^2 / (2*R)", {{"R", 50.0}}, context);
  EXPECT_EQ(gap.expression(), "x^2 / (2*R)");
  // x^2 / 100 at x = 0, 1, 10, -5 (y is ignored).
  EXPECT_DOUBLE_EQ(gap(0.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(gap(1.0, 0.0), 0.01);
  EXPECT_DOUBLE_EQ(gap(10.0, 3.0), 1.0);
  EXPECT_DOUBLE_EQ(gap(-5.0, 7.0), 0.25);
}

TEST(GapFunction, UsesBothVariables) {
  const GapFunction gap("x*y - 2*y", {}, context);
  EXPECT_DOUBLE_EQ(gap(2.0, 3.0), 0.0);   // 6 - 6
  EXPECT_DOUBLE_EQ(gap(1.5, -2.0), 1.0);  // -3 + 4
  EXPECT_DOUBLE_EQ(gap(0.0, 0.5), -1.0);  // 0 - 1
}

TEST(GapFunction, SeveralConstantsAndBuiltinFunctions) {
  const GapFunction line("a*x + b", {{"a", 2.0}, {"b", -1.0}}, context);
  EXPECT_DOUBLE_EQ(line(3.0, 0.0), 5.0);
  const GapFunction radius("sqrt(x^2 + y^2) - r0", {{"r0", 1.0}}, context);
  EXPECT_DOUBLE_EQ(radius(3.0, 4.0), 4.0);
  const GapFunction unary_minus("-x^2", {}, context);
  EXPECT_DOUBLE_EQ(unary_minus(3.0, 0.0), -9.0);  // -(x^2), not (-x)^2
}

TEST(GapFunction, SyntaxErrorGivesContextAndPosition) {
  const std::string expression = "x + * 2";
  const std::string message =
      error_message([&] { const GapFunction gap(expression, {}, context); });
  EXPECT_NE(message.find(context), std::string::npos) << message;
  EXPECT_NE(message.find("position 4"), std::string::npos) << message;  // the '*'
  EXPECT_NE(message.find(expression), std::string::npos) << message;
}

TEST(GapFunction, MissingParenthesisIsReported) {
  const std::string message = error_message([&] {
    const GapFunction gap("x^2 / (2*R", {{"R", 50.0}}, context);
  });
  EXPECT_NE(message.find(context), std::string::npos) << message;
  EXPECT_NE(message.find("parenthesis"), std::string::npos) << message;
}

TEST(GapFunction, UnknownVariableIsNamed) {
  const std::string message = error_message([&] { const GapFunction gap("x + w", {}, context); });
  EXPECT_NE(message.find(context), std::string::npos) << message;
  EXPECT_NE(message.find("\"w\""), std::string::npos) << message;
  EXPECT_NE(message.find("position 4"), std::string::npos) << message;
}

TEST(GapFunction, UndefinedConstantIsAnUnknownName) {
  const std::string message =
      error_message([&] { const GapFunction gap("x^2 / (2*R)", {}, context); });
  EXPECT_NE(message.find("\"R\""), std::string::npos) << message;
}

TEST(GapFunction, EmptyExpressionIsRejected) {
  const std::string message = error_message([&] { const GapFunction gap("", {}, context); });
  EXPECT_NE(message.find(context), std::string::npos) << message;
  EXPECT_NE(message.find("empty"), std::string::npos) << message;
}

TEST(GapFunction, ConstantCannotHideAVariable) {
  for (const std::string name : {"x", "y", "z"}) {
    const std::string message = error_message([&] {
      const GapFunction gap(name, {{name, 1.0}}, context);
    });
    EXPECT_NE(message.find(context), std::string::npos) << message;
    EXPECT_NE(message.find("'" + name + "'"), std::string::npos) << message;
  }
}

TEST(GapFunction, ThirdVariableOfSolidBodies) {
  const GapFunction sphere("(x^2 + y^2 + z^2) / (2*R)", {{"R", 2.0}}, context);
  EXPECT_DOUBLE_EQ(sphere(1.0, 2.0, 3.0), 14.0 / 4.0);
  EXPECT_DOUBLE_EQ(sphere(1.0, 2.0), 5.0 / 4.0);  // z = 0 on plane bodies
  const std::string message = error_message([&] { static_cast<void>(sphere(0.0, 0.0, 0.0)); });
  EXPECT_TRUE(message.empty()) << message;
  const GapFunction pole("1/z", {}, context);
  const std::string pole_message = error_message([&] { static_cast<void>(pole(1.0, 2.0, 0.0)); });
  EXPECT_NE(pole_message.find("not finite at (x, y, z) = (1, 2, 0)"), std::string::npos)
      << pole_message;
}

TEST(GapFunction, NonFiniteConstantIsRejected) {
  const double infinity = std::numeric_limits<double>::infinity();
  const std::string message = error_message([&] {
    const GapFunction gap("x + R", {{"R", infinity}}, context);
  });
  EXPECT_NE(message.find("'R'"), std::string::npos) << message;
  EXPECT_NE(message.find("finite"), std::string::npos) << message;
}

TEST(GapFunction, NonFiniteValueThrowsWhereItOccurs) {
  // Parsing evaluates at (0, 0, 0) without checking the value; evaluation checks it.
  const GapFunction gap("1/x", {}, context);
  EXPECT_DOUBLE_EQ(gap(4.0, 0.0), 0.25);
  const std::string message = error_message([&] { static_cast<void>(gap(0.0, 2.0)); });
  EXPECT_NE(message.find(context), std::string::npos) << message;
  EXPECT_NE(message.find("not finite"), std::string::npos) << message;
  const GapFunction root("sqrt(x)", {}, context);
  EXPECT_THROW(static_cast<void>(root(-1.0, 0.0)), InputError);
}

TEST(GapFunction, SeparateObjectsEvaluateConcurrently) {
  // Thread compatibility: one object per thread. Sum of x^2/(2R) over x = 0..999 with R = 50
  // is sum(x^2)/100 = 999*1000*1999/6/100.
  const double expected = 999.0 * 1000.0 * 1999.0 / 6.0 / 100.0;
  double sums[2] = {0.0, 0.0};
  auto work = [&sums](int slot) {
    const GapFunction gap("x^2 / (2*R)", {{"R", 50.0}}, context);
    for (int i = 0; i < 1000; ++i) sums[slot] += gap(i, 0.0);
  };
  std::thread first(work, 0);
  std::thread second(work, 1);
  first.join();
  second.join();
  EXPECT_NEAR(sums[0], expected, 1e-12 * expected);
  EXPECT_NEAR(sums[1], expected, 1e-12 * expected);
}

}  // namespace
}  // namespace robin
