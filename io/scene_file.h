#pragma once
// Scene files: INI read with Boost.Program_options' config-file parser. Sections
// [slider] [friction] [patch] [initial] [push] [push.1] [push.2] ... [program] [sim] [log]
// [noise]; keys and defaults in datasets/README.md. Unknown keys, missing required keys and
// bad values throw SceneError naming the file and the key.

#include <stdexcept>
#include <string>

#include "datasets/logged_scene.h"

namespace slideid {

/// Bad scene file: message names the file and the key.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a scene file: the scene and its log spec. Throws SceneError.
LoggedScene LoadScene(const std::string& path);
/// Same, from text (source names it in messages).
LoggedScene ParseScene(const std::string& ini_text, const std::string& source);

}  // namespace slideid
