// Expressions: precedence, degrees, short-circuit logic, folding and located errors.
#include <cmath>

#include "lsystem/expr.h"
#include "tests/lsystem/lsystem_test_util.h"

namespace sylva::lsys {
namespace {

using testing::derive_text;
using testing::parse_error;

// Evaluates a constant expression through the axiom: axiom: X(<expr>).
std::string value_of(const std::string& expr) { return derive_text("axiom: X(" + expr + ")\nsteps: 0\n"); }

TEST(Expressions, FollowUsualPrecedenceAndAssociativity) {
  EXPECT_EQ(value_of("1+2*3"), "X(7)");
  EXPECT_EQ(value_of("(1+2)*3"), "X(9)");
  EXPECT_EQ(value_of("2^3^2"), "X(512)");     // right-associative power
  EXPECT_EQ(value_of("-2^2"), "X(-4)");       // unary minus binds looser than ^
  EXPECT_EQ(value_of("2^-1"), "X(0.5)");
  EXPECT_EQ(value_of("10-4-3"), "X(3)");      // left-associative
  EXPECT_EQ(value_of("8/4/2"), "X(1)");
  EXPECT_EQ(value_of("1 < 2 == 1"), "X(1)");  // comparison before equality
  EXPECT_EQ(value_of("!0 + !5"), "X(1)");
  EXPECT_EQ(value_of(".5 + 1e-3"), "X(0.501)");
}

TEST(Expressions, TrigonometryIsInDegreesAndExactAtRightAngles) {
  EXPECT_EQ(value_of("sin(90)"), "X(1)");
  EXPECT_EQ(value_of("sin(180)"), "X(0)");
  EXPECT_EQ(value_of("cos(90)"), "X(0)");
  EXPECT_EQ(value_of("cos(-270)"), "X(0)");
  EXPECT_EQ(value_of("cos(360)"), "X(1)");
  EXPECT_EQ(value_of("atan2(1, 0)"), "X(90)");
  EXPECT_EQ(value_of("asin(1)"), "X(90)");
  EXPECT_EQ(value_of("acos(-1)"), "X(180)");
  EXPECT_NEAR(sin_deg(30), 0.5, 1e-16);
  EXPECT_NEAR(cos_deg(60), 0.5, 1e-15);
  EXPECT_NEAR(sin_deg(360.0 * 2777 + 30), 0.5, 1e-15);  // reduced exactly before conversion
}

TEST(Expressions, EveryFunctionComputesItsValue) {
  EXPECT_EQ(value_of("sqrt(16)"), "X(4)");
  EXPECT_EQ(value_of("exp(0)"), "X(1)");
  EXPECT_EQ(value_of("log(1)"), "X(0)");
  EXPECT_EQ(value_of("pow(2, 10)"), "X(1024)");
  EXPECT_EQ(value_of("abs(-3)"), "X(3)");
  EXPECT_EQ(value_of("floor(-1.5)"), "X(-2)");
  EXPECT_EQ(value_of("ceil(1.2)"), "X(2)");
  EXPECT_EQ(value_of("min(3, -1)"), "X(-1)");
  EXPECT_EQ(value_of("max(3, -1)"), "X(3)");
  EXPECT_EQ(value_of("clamp(5, 0, 2)"), "X(2)");
  EXPECT_EQ(value_of("tan(180)"), "X(0)");
  EXPECT_NEAR(std::stod(value_of("tan(45)").substr(2)), 1.0, 1e-15);
  EXPECT_EQ(value_of("pi"), "X(3.141592653589793)");
}

TEST(Expressions, AndOrShortCircuitSoAGuardedDivisionIsSafe) {
  // x != 0 && 1/x > 2 must not divide by zero when x is 0.
  EXPECT_EQ(derive_text("axiom: A(0)\nA(x) : x != 0 && 1/x > 2 -> B\n"), "A(0)");
  EXPECT_EQ(derive_text("axiom: A(0)\nA(x) : x == 0 || 1/x > 2 -> B\n"), "B");
  EXPECT_EQ(derive_text("axiom: A(0.25)\nA(x) : x != 0 && 1/x > 2 -> B\n"), "B");
}

TEST(Expressions, DefinesAreConstantsAndFoldAtParseTime) {
  auto g = testing::parse_ok("#define A 2\n#define B A*3\naxiom: X(B)\nX(x) -> Y(x*B)\n");
  EXPECT_EQ(g.axiom.params[0], 6);
  // The successor argument reads a parameter, so it is compiled; the axiom's is folded.
  ASSERT_EQ(g.productions.size(), 1u);
  EXPECT_EQ(g.productions[0].successor.args[0].kind, Expr::Kind::kProgram);
  EXPECT_EQ(derive_text("#define A 2\n#define B A*3\naxiom: X(B)\nX(x) -> Y(x*B)\n"), "Y(36)");
}

TEST(Expressions, AFormalParameterAloneIsReadWithoutTheMachine) {
  auto g = testing::parse_ok("axiom: A(1,2)\nA(x,y) -> B(y,x)\n");
  EXPECT_EQ(g.productions[0].successor.args[0].kind, Expr::Kind::kSlot);
  EXPECT_EQ(derive_text("axiom: A(1,2)\nA(x,y) -> B(y,x)\n"), "B(2,1)");
}

TEST(ExpressionErrors, DivisionByZeroInADefineIsLocatedAtTheOperator) {
  Diagnostic d = parse_error("#define X 1/0\naxiom: F\n");
  EXPECT_EQ(d.loc.line, 1u);
  EXPECT_EQ(d.loc.column, 12u);
  EXPECT_NE(d.message.find("division by zero"), std::string::npos);
}

TEST(ExpressionErrors, NaNAndInfinityAreErrorsNotSilentValues) {
  Diagnostic d = parse_error("axiom: F(sqrt(-1))\n");
  EXPECT_NE(d.message.find("not finite"), std::string::npos);
  EXPECT_EQ(d.loc.column, 10u);
  d = parse_error("axiom: F(log(0))\n");
  EXPECT_NE(d.message.find("not finite"), std::string::npos);
  d = parse_error("axiom: F(tan(90))\n");
  EXPECT_NE(d.message.find("not finite"), std::string::npos);
  d = parse_error("axiom: F(10^400)\n");
  EXPECT_NE(d.message.find("not finite"), std::string::npos);
}

TEST(ExpressionErrors, ALiteralBeyondDoubleRangeIsOutOfRange) {
  Diagnostic d = parse_error("axiom: F(1e400)\n");
  EXPECT_NE(d.message.find("out of range"), std::string::npos);
  EXPECT_EQ(d.loc.column, 10u);
}

TEST(ExpressionErrors, UnknownNamesFunctionsAndArityAreReported) {
  EXPECT_NE(parse_error("axiom: F(len)\n").message.find("unknown name 'len'"), std::string::npos);
  EXPECT_NE(parse_error("axiom: F(foo(1))\n").message.find("unknown function 'foo'"), std::string::npos);
  Diagnostic d = parse_error("axiom: F(sin(1, 2))\n");
  EXPECT_NE(d.message.find("expects 1 argument, got 2"), std::string::npos);
  EXPECT_EQ(d.loc.column, 10u);
  EXPECT_NE(parse_error("axiom: F(uniform(1))\n").message.find("expects 2 arguments"), std::string::npos);
  EXPECT_NE(parse_error("axiom: F(sin)\n").message.find("needs arguments"), std::string::npos);
}

TEST(ExpressionErrors, DeepNestingIsAnErrorNotAStackOverflow) {
  std::string deep(100000, '(');
  deep += "1";
  deep += std::string(100000, ')');
  Diagnostic d = parse_error("axiom: F(" + deep + ")\n");
  EXPECT_NE(d.message.find("nested too deeply"), std::string::npos);
  std::string minus(100000, '-');
  d = parse_error("axiom: F(" + minus + "1)\n");
  EXPECT_NE(d.message.find("nested too deeply"), std::string::npos);
}

TEST(ExpressionErrors, DerivationErrorsNameTheProductionAndTheModule) {
  auto g = testing::parse_ok("axiom: A(2)\np1: A(x) -> A(x-1)B(1/x)\n");
  auto w = derive(g, DeriveOptions{3, std::nullopt, 1000, {}});
  ASSERT_FALSE(w.ok());
  const Diagnostic& d = w.error();
  EXPECT_EQ(d.loc.line, 2u);
  EXPECT_EQ(d.loc.column, 22u);  // the '/' of 1/x
  EXPECT_NE(d.message.find("division by zero"), std::string::npos);
  EXPECT_NE(d.message.find("p1: A(x) -> A(x-1)B(1/x)"), std::string::npos);
  EXPECT_NE(d.message.find("rewriting module A(0)"), std::string::npos);
  EXPECT_NE(d.message.find("step 3"), std::string::npos);
}

}  // namespace
}  // namespace sylva::lsys
