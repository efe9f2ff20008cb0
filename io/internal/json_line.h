#pragma once
// The one-line JSON layout every JSON our tools print shares (io/result_json.h): ", "
// between items and ": " after keys, on one line, numbers in their shortest round-trip
// form, a number that is not finite written as null. Internal to io/.

#include <cmath>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace slideid::json_line {

/// Keys keep the order in which they are inserted (and in which a reader finds them).
using Json = nlohmann::ordered_json;

/// A number, or null when it is not finite (JSON has no NaN or infinity).
inline Json NumberOrNull(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

/// A scalar as nlohmann writes it: strings escaped (invalid UTF-8 replaced, never thrown),
/// doubles in their shortest round-trip form.
inline std::string Scalar(const Json& j) {
  return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

/// The start of `j` as Scalar writes it (nlohmann's compact dump), at least `max_chars`
/// characters of it when it is longer: for a message quoting a value read from a file. Unlike
/// dump, it stops there, so a value nested a million levels deep costs no deeper recursion
/// than `max_chars` (each level writes a bracket) instead of overflowing the stack.
template <typename AnyJson>
void AppendStart(const AnyJson& j, std::size_t max_chars, std::string* out) {
  if (out->size() > max_chars) return;
  if (!j.is_structured()) {
    *out += j.dump(-1, ' ', false, AnyJson::error_handler_t::replace);
    return;
  }
  *out += j.is_object() ? '{' : '[';
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (out->size() > max_chars) return;
    if (it != j.begin()) *out += ',';
    if (j.is_object()) {
      *out += AnyJson(it.key()).dump(-1, ' ', false, AnyJson::error_handler_t::replace) + ":";
    }
    AppendStart(it.value(), max_chars, out);
  }
  if (out->size() <= max_chars) *out += j.is_object() ? '}' : ']';
}

/// At most `max_chars` characters of `j` as Scalar writes it, "..." marking a cut.
template <typename AnyJson>
std::string Brief(const AnyJson& j, std::size_t max_chars = 40) {
  std::string text;
  AppendStart(j, max_chars, &text);
  if (text.size() > max_chars) text = text.substr(0, max_chars) + "...";
  return text;
}

/// Appends `j` in the documented layout (nlohmann's compact dump has no spaces, its
/// indented dump has line breaks).
inline void Print(const Json& j, std::string* out) {
  if (!j.is_object() && !j.is_array()) {
    *out += Scalar(j);
    return;
  }
  *out += j.is_object() ? '{' : '[';
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it != j.begin()) *out += ", ";
    if (j.is_object()) *out += Scalar(Json(it.key())) + ": ";
    Print(it.value(), out);
  }
  *out += j.is_object() ? '}' : ']';
}

}  // namespace slideid::json_line
