#pragma once
// Text put into the HTML report: escaped, and numbers that never read "nan" or "inf".

#include <string>
#include <string_view>

namespace slideid {

/// `text` with &, <, >, " and ' replaced by their entities: safe in element content and in
/// quoted attribute values alike.
std::string HtmlEscape(std::string_view text);

/// `value` with `significant` digits (%.*g), or `missing` when it is not finite (a report
/// says "—" or "not identifiable", never "nan").
std::string HtmlNumber(double value, int significant = 4, std::string_view missing = "—");

/// What the report prints for a value that is not finite.
constexpr std::string_view kMissingValue = "—";

}  // namespace slideid
