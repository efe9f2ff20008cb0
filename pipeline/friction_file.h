#pragma once
// The text of the file given to --friction (a fitted result, `identify --json`), read by the
// options of predict and advise-push.

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace slideid::cli {

/// The whole text of `path`; throws std::runtime_error naming it when it cannot be opened.
inline std::string ReadFrictionFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the friction (identify --json)");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace slideid::cli
