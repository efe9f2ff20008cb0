#include "forward_model/number_format.h"

#include <charconv>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace slideid {
namespace number_format_internal {
namespace {

const char* KindName(ArgType::Kind kind) {
  switch (kind) {
    case ArgType::kInteger:
      return "an integer";
    case ArgType::kFloating:
      return "a floating-point number";
    case ArgType::kString:
      return "a string";
    case ArgType::kPointer:
      return "a pointer";
  }
  return "?";
}

/// Size of the integer an integer conversion reads, from its length modifier.
std::size_t IntegerSize(const std::string& length) {
  if (length.empty() || length == "h" || length == "hh") return sizeof(int);  // promoted
  if (length == "l") return sizeof(long);
  if (length == "ll") return sizeof(long long);
  if (length == "j") return sizeof(std::intmax_t);
  if (length == "z") return sizeof(std::size_t);
  if (length == "t") return sizeof(std::ptrdiff_t);
  return 0;  // "L": not an integer length
}

}  // namespace

void CheckArguments(const char* format, std::initializer_list<ArgType> types) {
  if (format == nullptr) throw std::logic_error("Printf: the format is null");
  const ArgType* next = types.begin();
  int number = 0;  // of the argument read last, from 1
  auto fail = [&](const std::string& what) {
    throw std::logic_error("Printf(\"" + std::string(format) + "\"): " + what);
  };
  // Reads the next argument for `conversion`: it must be of `kind` and, for numbers, `size`.
  auto take = [&](const std::string& conversion, ArgType::Kind kind, std::size_t size) {
    ++number;
    if (next == types.end()) {
      fail("no argument " + std::to_string(number) + " for " + conversion);
    }
    const ArgType given = *next++;
    const bool fits = kind == ArgType::kPointer
                          ? given.kind == ArgType::kPointer || given.kind == ArgType::kString
                          : given.kind == kind && (kind == ArgType::kString || given.size == size);
    if (!fits) {
      fail("argument " + std::to_string(number) + " is " + KindName(given.kind) + " of " +
           std::to_string(given.size) + " bytes, but " + conversion + " reads " + KindName(kind) +
           (kind == ArgType::kString || kind == ArgType::kPointer
                ? std::string()
                : " of " + std::to_string(size) + " bytes"));
    }
  };
  for (const char* p = format; *p != '\0'; ++p) {
    if (*p != '%') continue;
    const char* start = p++;
    if (*p == '%') continue;
    while (*p != '\0' && std::strchr("-+ #0'", *p) != nullptr) ++p;
    // A '*' width or precision is read from an int argument before the value.
    if (*p == '*') {
      take("a '*' width", ArgType::kInteger, sizeof(int));
      ++p;
    } else {
      while (*p >= '0' && *p <= '9') ++p;
    }
    if (*p == '.') {
      ++p;
      if (*p == '*') {
        take("a '*' precision", ArgType::kInteger, sizeof(int));
        ++p;
      } else {
        while (*p >= '0' && *p <= '9') ++p;
      }
    }
    std::string length;
    while (*p != '\0' && std::strchr("hlLjzt", *p) != nullptr) length += *p++;
    if (*p == '\0') fail("the format ends inside a conversion");
    const std::string conversion(start, p + 1);
    const std::size_t integer = IntegerSize(length);
    switch (*p) {
      case 'd':
      case 'i':
      case 'o':
      case 'u':
      case 'x':
      case 'X':
        if (integer == 0) fail("unknown length in " + conversion);
        take(conversion, ArgType::kInteger, integer);
        break;
      case 'c':
        if (!length.empty()) fail("wide characters are not supported: " + conversion);
        take(conversion, ArgType::kInteger, sizeof(int));
        break;
      case 'f':
      case 'F':
      case 'e':
      case 'E':
      case 'g':
      case 'G':
      case 'a':
      case 'A':
        if (!length.empty() && length != "l" && length != "L") {
          fail("unknown length in " + conversion);
        }
        take(conversion, ArgType::kFloating, length == "L" ? sizeof(long double) : sizeof(double));
        break;
      case 's':
        if (!length.empty()) fail("wide strings are not supported: " + conversion);
        take(conversion, ArgType::kString, 0);
        break;
      case 'p':
        take(conversion, ArgType::kPointer, 0);
        break;
      default:  // %n writes through its argument; %1$d and the like are not read here
        fail("unsupported conversion " + conversion);
    }
  }
  if (next != types.end()) {
    fail(std::to_string(types.size()) + " arguments for " + std::to_string(number) +
         " conversions");
  }
}

std::string PrintUnchecked(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int length = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  if (length < 0) {
    va_end(again);
    throw std::runtime_error("Printf(\"" + std::string(format) + "\"): vsnprintf failed");
  }
  std::string text(static_cast<std::size_t>(length), '\0');
  std::vsnprintf(text.data(), text.size() + 1, format, again);  // + 1: the string's own '\0'
  va_end(again);
  return text;
}

}  // namespace number_format_internal

std::string ExactNumber(double value) {
  // At most 24 characters ("-2.2250738585072014e-308"), so this buffer never truncates;
  // these numbers fill whole log files, hence one snprintf, not Printf's two.
  char buffer[32];
  const int length = std::snprintf(buffer, sizeof buffer, "%.17g", value);
  return std::string(buffer, static_cast<std::size_t>(length));
}

std::string ShortNumber(double value) {
  char buffer[32];  // as ExactNumber's: at most 24 characters
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace slideid
