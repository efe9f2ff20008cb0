// The benchmark programs' command-line reader (benchmarks/bench_args.h): values read whole,
// and every bad or missing value an error that names the option and the value.

#include "benchmarks/bench_args.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace slideid {
namespace {

/// An argv over `words` (argv[0] is the program), as main() receives it.
class Argv {
 public:
  explicit Argv(std::vector<std::string> words) : words_(std::move(words)) {
    words_.insert(words_.begin(), "program");
    for (std::string& w : words_) pointers_.push_back(w.data());
  }
  int argc() { return static_cast<int>(pointers_.size()); }
  char** argv() { return pointers_.data(); }

 private:
  std::vector<std::string> words_;
  std::vector<char*> pointers_;
};

/// The message of the std::invalid_argument that reading `words`' first option's value with
/// `read` throws; "" when it throws none.
template <typename Read>
std::string ErrorOf(std::vector<std::string> words, Read read) {
  Argv a(std::move(words));
  bench::Args args(a.argc(), a.argv());
  EXPECT_TRUE(args.Next());
  try {
    read(args);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(BenchArgs, ReadsOptionsAndTheirValuesInOrder) {
  Argv a({"--logs", "30", "--quick", "--timestep", "2.5e-4", "--lengths", "100,1000", "--methods",
          "closed-form,trajectory", "--threads", "-3"});
  bench::Args args(a.argc(), a.argv());
  ASSERT_TRUE(args.Next());
  EXPECT_TRUE(args.Is("--logs"));
  EXPECT_EQ(args.Integer(1), 30);
  ASSERT_TRUE(args.Next());
  EXPECT_EQ(args.option(), "--quick");
  EXPECT_STREQ(args.arg(), "--quick");
  ASSERT_TRUE(args.Next());
  EXPECT_EQ(args.Number(), 2.5e-4);
  ASSERT_TRUE(args.Next());
  EXPECT_EQ(args.Integers(), (std::vector<int>{100, 1000}));
  ASSERT_TRUE(args.Next());
  EXPECT_EQ(args.List(), (std::vector<std::string>{"closed-form", "trajectory"}));
  ASSERT_TRUE(args.Next());
  EXPECT_EQ(args.Integer(), -3);  // no bound asked for: the program checks it
  EXPECT_FALSE(args.Next());
}

TEST(BenchArgs, BadOrMissingValuesAreErrorsNamingTheOptionAndTheValue) {
  auto integer = [](bench::Args& a) { a.Integer(); };
  auto at_least_one = [](bench::Args& a) { a.Integer(1); };
  auto number = [](bench::Args& a) { a.Number(); };
  auto integers = [](bench::Args& a) { a.Integers(); };
  EXPECT_EQ(ErrorOf({"--logs"}, integer), "--logs needs a value");
  EXPECT_EQ(ErrorOf({"--logs", "x"}, integer), "--logs: 'x' is not an integer");
  EXPECT_EQ(ErrorOf({"--logs", "12abc"}, integer), "--logs: '12abc' is not an integer");
  EXPECT_EQ(ErrorOf({"--logs", ""}, integer), "--logs: '' is not an integer");
  EXPECT_EQ(ErrorOf({"--logs", "99999999999"}, integer), "--logs: '99999999999' is not an integer");
  EXPECT_EQ(ErrorOf({"--logs", "0"}, at_least_one), "--logs: '0' is not an integer >= 1");
  EXPECT_EQ(ErrorOf({"--timestep", "1ms"}, number), "--timestep: '1ms' is not a finite number");
  EXPECT_EQ(ErrorOf({"--timestep", "inf"}, number), "--timestep: 'inf' is not a finite number");
  EXPECT_EQ(ErrorOf({"--lengths", "100,,5000"}, integers),
            "--lengths: '' in '100,,5000' is not an integer");
  EXPECT_EQ(ErrorOf({"--lengths", "100,1e3"}, integers),
            "--lengths: '1e3' in '100,1e3' is not an integer");
}

}  // namespace
}  // namespace slideid
