#pragma once
// The command line of the plain benchmark programs (coverage, error_vs_time, scene_suite,
// stability_sweep, mujoco_baseline, and prediction_benchmark's own options), read one option
// at a time.
//
// Why one reader: each program had its own loop and its own way of reading a number
// (std::stoi, atoi, atof, strtol), so "--logs x" gave an exception saying only "stoi", a
// silent 0, or a clear message, depending on the program; "--logs 12abc" was 12 in some.
// Here a missing value, or a value that is not wholly a number of the kind asked for, throws
// std::invalid_argument naming the option and the value. What an unknown option does (usage
// and exit 2, an exception, or handing it on to Google Benchmark) stays each program's choice,
// as do the exit codes.
//
//   bench::Args args(argc, argv);
//   while (args.Next()) {
//     if (args.Is("--logs")) logs = args.Integer(1);
//     else if (args.Is("--csv")) csv_path = args.Value();
//     else ...  // args.option() is the unknown option
//   }

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace slideid {
namespace bench {

/// Walks argv[1], ..., argv[argc - 1]; an option's value, when it takes one, is the argument
/// after it ("--logs 30", not "--logs=30").
class Args {
 public:
  Args(int argc, char** argv) : argc_(argc), argv_(argv) {}

  /// Moves to the next option; false when none is left.
  bool Next() {
    if (++i_ >= argc_) return false;
    option_ = argv_[i_];
    return true;
  }
  /// The current option, e.g. "--logs".
  const std::string& option() const { return option_; }
  /// The current option as argv holds it (to hand it on to another parser).
  char* arg() const { return argv_[i_]; }
  /// Whether the current option is `name`.
  bool Is(const char* name) const { return option_ == name; }

  /// The option's value: the next argument, consumed. Throws when there is none.
  std::string Value() {
    if (i_ + 1 >= argc_) throw std::invalid_argument(option_ + " needs a value");
    return argv_[++i_];
  }
  /// The value as an int of at least `min` (decimal, nothing after the digits).
  int Integer(int min = std::numeric_limits<int>::min()) {
    const std::string v = Value();
    const bool bounded = min != std::numeric_limits<int>::min();
    return ToInteger(v, min, bounded ? " >= " + std::to_string(min) : "", v);
  }
  /// The value as a finite double (anything strtod reads, nothing after it).
  double Number() {
    const std::string v = Value();
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end || errno == ERANGE || !std::isfinite(x)) {
      throw std::invalid_argument(option_ + ": '" + v + "' is not a finite number");
    }
    return x;
  }
  /// The value split at commas: "a,b" -> {"a", "b"}; an empty item stays (",b" -> {"", "b"}).
  std::vector<std::string> List() { return Split(Value()); }
  /// The value as comma-separated ints: "100,1000,5000" -> {100, 1000, 5000}.
  std::vector<int> Integers() {
    const std::string v = Value();
    std::vector<int> out;
    for (const std::string& item : Split(v)) {
      out.push_back(ToInteger(item, std::numeric_limits<int>::min(), "", v));
    }
    return out;
  }

 private:
  static std::vector<std::string> Split(const std::string& text) {
    std::vector<std::string> out;
    size_t pos = 0;
    while (pos <= text.size()) {
      const size_t comma = std::min(text.find(',', pos), text.size());
      out.push_back(text.substr(pos, comma - pos));
      pos = comma + 1;
    }
    return out;
  }
  /// `text` as an int >= min; the error names the option, `text` and (when it is a list) the
  /// whole value, and `bound` ("" or " >= 1").
  int ToInteger(const std::string& text, int min, const std::string& bound,
                const std::string& whole) const {
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(text.c_str(), &end, 10);
    if (text.empty() || *end || errno == ERANGE || n < min || n > std::numeric_limits<int>::max()) {
      const std::string in = whole == text ? "" : " in '" + whole + "'";
      throw std::invalid_argument(option_ + ": '" + text + "'" + in + " is not an integer" + bound);
    }
    return static_cast<int>(n);
  }

  int argc_;
  char** argv_;
  int i_ = 0;  ///< argv index of the current option
  std::string option_;
};

}  // namespace bench
}  // namespace slideid
