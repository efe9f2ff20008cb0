#pragma once
// Numbers as text, written one way in every room: printf-style formatting into a string as
// long as it needs (no fixed buffer to truncate it), checked against its arguments, and the
// two spellings of a double that read back to the same double. Here, in the library every
// other one links, so that no room keeps a private copy.

#include <cstddef>
#include <initializer_list>
#include <string>
#include <type_traits>

namespace slideid {

/// printf's `format` filled in with `args`, at whatever length that takes. Arguments are
/// numbers, pointers, C strings and std::string (printed by %s). Each is checked against
/// its conversion before anything is printed: where printf would read garbage (an int for
/// %f, a double or a size_t for %d, too few or too many arguments, %n, positional %1$d),
/// this throws std::logic_error naming the format.
template <typename... Args>
std::string Printf(const char* format, const Args&... args);

/// The text "%.17g" writes: 17 significant digits, which read back (strtod, std::stod) to
/// the same double; "nan", "inf", "-inf" and "-0" as printf spells them. Not the shortest
/// (0.1 is "0.10000000000000001"): the push logs, dataset metadata and scene texts have
/// always been written this way, and a file written again stays byte for byte the same.
std::string ExactNumber(double value);

/// The shortest text that reads back to the same double (std::to_chars): "0.1", "1e+300",
/// "5e-324"; "nan", "inf", "-inf" and "-0" as ExactNumber spells them.
std::string ShortNumber(double value);

// ---- implementation -----------------------------------------------------------------------

namespace number_format_internal {

/// What a printf argument is once passed through `...` (after the default promotions).
struct ArgType {
  enum Kind { kInteger, kFloating, kString, kPointer };
  Kind kind;
  std::size_t size;  ///< bytes
};

template <typename T>
inline constexpr bool kAlwaysFalse = false;

template <typename T>
constexpr ArgType TypeOf() {
  using U = std::remove_cv_t<std::decay_t<T>>;
  if constexpr (std::is_same_v<U, std::string> || std::is_same_v<U, const char*> ||
                std::is_same_v<U, char*>) {
    return {ArgType::kString, sizeof(const char*)};
  } else if constexpr (std::is_integral_v<U>) {
    return {ArgType::kInteger, sizeof(U) < sizeof(int) ? sizeof(int) : sizeof(U)};
  } else if constexpr (std::is_floating_point_v<U>) {
    return {ArgType::kFloating, sizeof(U) < sizeof(double) ? sizeof(double) : sizeof(U)};
  } else if constexpr (std::is_pointer_v<U> || std::is_null_pointer_v<U>) {
    return {ArgType::kPointer, sizeof(const void*)};
  } else {
    static_assert(kAlwaysFalse<U>,
                  "Printf takes numbers, pointers, C strings and std::string (cast an enum)");
    return {ArgType::kPointer, 0};
  }
}

/// What goes through `...`: a std::string as its characters, anything else as it is.
inline const char* Pass(const std::string& s) { return s.c_str(); }
template <typename T>
auto Pass(const T& value) {
  return value;  // an array decays to its pointer here
}

/// Throws std::logic_error unless `types` are, in order, what `format`'s conversions read.
void CheckArguments(const char* format, std::initializer_list<ArgType> types);

/// vsnprintf twice: once for the length, once to write.
std::string PrintUnchecked(const char* format, ...);

}  // namespace number_format_internal

template <typename... Args>
std::string Printf(const char* format, const Args&... args) {
  namespace internal = number_format_internal;
  internal::CheckArguments(format, {internal::TypeOf<Args>()...});
  return internal::PrintUnchecked(format, internal::Pass(args)...);
}

}  // namespace slideid
