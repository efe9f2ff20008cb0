#include "report/html_text.h"

#include <cmath>

#include "forward_model/number_format.h"

namespace slideid {

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

std::string HtmlNumber(double value, int significant, std::string_view missing) {
  if (!std::isfinite(value)) return std::string(missing);
  return Printf("%.*g", significant, value);
}

}  // namespace slideid
