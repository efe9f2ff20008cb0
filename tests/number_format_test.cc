#include "forward_model/number_format.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace slideid {
namespace {

/// Awkward doubles: not exact in decimal, the ends of the range, subnormals, -0.
std::vector<double> AwkwardValues() {
  return {0.1,
          1.0 / 3.0,
          -2.0 / 3.0,
          0.1 + 0.2,
          3.141592653589793,
          1e308,
          DBL_MAX,
          -DBL_MAX,
          DBL_MIN,
          std::numeric_limits<double>::denorm_min(),  // 5e-324
          2.2250738585072009e-308,                    // the largest subnormal
          -1.2345678901234567e-300,
          1e23,                // 9.9999999999999992e+22 in 17 digits
          9007199254740993.0,  // 2^53 + 1 rounds to 2^53
          123456789.125,
          1e-7,
          0.0,
          -0.0};
}

/// The double `text` reads back to, as strtod reads it (the readers use std::from_chars or
/// strtod).
double ReadBack(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  EXPECT_EQ(*end, '\0') << "'" << text << "' is not read whole";
  return value;
}

/// Same bits: -0.0 and 0.0 differ here, where == would call them equal.
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(ExactNumber, ReadsBackToTheSameDouble) {
  for (double v : AwkwardValues()) {
    const std::string text = ExactNumber(v);
    EXPECT_TRUE(SameBits(ReadBack(text), v)) << text;
  }
}

TEST(ExactNumber, SpellsNumbersAsPercentPoint17gAlwaysHas) {
  // The files written before it existed: the same bytes again.
  EXPECT_EQ(ExactNumber(0.1), "0.10000000000000001");
  EXPECT_EQ(ExactNumber(1.0 / 3.0), "0.33333333333333331");
  EXPECT_EQ(ExactNumber(0.5), "0.5");
  EXPECT_EQ(ExactNumber(1e308), "1e+308");
  EXPECT_EQ(ExactNumber(1e23), "9.9999999999999992e+22");
  EXPECT_EQ(ExactNumber(std::numeric_limits<double>::denorm_min()), "4.9406564584124654e-324");
  EXPECT_EQ(ExactNumber(-0.0), "-0");
  EXPECT_EQ(ExactNumber(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(ExactNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(ExactNumber(-std::numeric_limits<double>::infinity()), "-inf");
  for (double v : AwkwardValues()) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    EXPECT_EQ(ExactNumber(v), buffer);
  }
}

TEST(ShortNumber, ReadsBackToTheSameDoubleInTheFewestDigits) {
  for (double v : AwkwardValues()) {
    const std::string text = ShortNumber(v);
    EXPECT_TRUE(SameBits(ReadBack(text), v)) << text;
    EXPECT_LE(text.size(), ExactNumber(v).size()) << text;
  }
  EXPECT_EQ(ShortNumber(0.1), "0.1");
  EXPECT_EQ(ShortNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(ShortNumber(1e308), "1e+308");
  EXPECT_EQ(ShortNumber(std::numeric_limits<double>::denorm_min()), "5e-324");
  EXPECT_EQ(ShortNumber(-0.0), "-0");
  EXPECT_EQ(ShortNumber(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(ShortNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(ShortNumber(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(Printf, WritesWhatSnprintfWrites) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%-8s|%+.3e|%5.1f%%|%zu|%lld|%c|%x|%.0f|%g", "name",
                -1234.5678, 99.95, std::size_t{42}, -7LL, 'q', 255u, 2.5, 1e-5);
  EXPECT_EQ(Printf("%-8s|%+.3e|%5.1f%%|%zu|%lld|%c|%x|%.0f|%g", std::string("name"), -1234.5678,
                   99.95, std::size_t{42}, -7LL, 'q', 255u, 2.5, 1e-5),
            buffer);
  EXPECT_EQ(Printf("%*.*f|%-*d|", 8, 3, 3.14159, 4, 7), "   3.142|7   |");
  EXPECT_EQ(Printf("100%% sure"), "100% sure");
  EXPECT_EQ(Printf(""), "");
  EXPECT_EQ(Printf("%s and %s", "literal", std::string("string")), "literal and string");
  EXPECT_EQ(Printf("%d %hd %u", true, short{-3}, 5u), "1 -3 5");
  EXPECT_EQ(Printf("%.3g %lf", 1.0f, 0.25), "1 0.250000");
}

TEST(Printf, DoesNotTruncateLongTexts) {
  const std::string long_word(5000, 'x');
  const std::string text = Printf("[%s] = %d", long_word, 7);
  EXPECT_EQ(text.size(), 5006u);
  EXPECT_EQ(text, "[" + long_word + "] = 7");
  // 1e300 in fixed notation: 301 digits and the decimals.
  const std::string wide = Printf("%.2f", 1e300);
  EXPECT_EQ(wide.size(), 304u);
  EXPECT_EQ(wide.substr(wide.size() - 3), ".00");
  EXPECT_TRUE(SameBits(ReadBack(wide), 1e300));
  EXPECT_EQ(Printf("%1000d", 1).size(), 1000u);
}

TEST(Printf, ThrowsWhereSnprintfWouldReadTheWrongArgument) {
  EXPECT_THROW(Printf("%f", 1), std::logic_error);               // an int for a double
  EXPECT_THROW(Printf("%d", 1.0), std::logic_error);             // a double for an int
  EXPECT_THROW(Printf("%d", std::size_t{1}), std::logic_error);  // 8 bytes for 4
  EXPECT_THROW(Printf("%zu", 1), std::logic_error);              // 4 bytes for 8
  EXPECT_THROW(Printf("%s", 1), std::logic_error);               // a number for a string
  EXPECT_THROW(Printf("%d and %d", 1), std::logic_error);        // too few
  EXPECT_THROW(Printf("%d", 1, 2), std::logic_error);            // too many
  EXPECT_THROW(Printf("%*d", 2.0, 1), std::logic_error);         // a double for the width
  EXPECT_THROW(Printf("%1$d", 1), std::logic_error);             // positional
  int written = 0;
  EXPECT_THROW(Printf("%n", &written), std::logic_error);  // writes through it
  EXPECT_THROW(Printf("%", 1), std::logic_error);          // ends inside a conversion
  EXPECT_THROW(Printf(nullptr), std::logic_error);
  try {
    Printf("t = %.3f s", 3);
    FAIL() << "no exception";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("t = %.3f s"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace slideid
