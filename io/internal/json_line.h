#pragma once
// The one-line JSON layout every JSON our tools print shares (io/result_json.h): ", "
// between items and ": " after keys, on one line, numbers in their shortest round-trip
// form, a number that is not finite written as null. Internal to io/.

#include <cmath>
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
