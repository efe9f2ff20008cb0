#include "plots/gnuplot.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <stdexcept>

#include "io/atomic_file.h"

namespace slideid {

bool PictureOptions::IsValid(std::string* why, bool automatic_height) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  auto outside = [](int px) { return px < kMinPicturePx || px > kMaxPicturePx; };
  if (out_png.empty()) return fail("plot: no output file");
  if (outside(width_px)) return fail("plot: width must be 200 to 20000 pixels");
  if (automatic_height && height_px != 0 && outside(height_px)) {
    return fail("plot: height must be 0 (automatic) or 200 to 20000 pixels");
  }
  if (!automatic_height && outside(height_px)) {
    return fail("plot: height must be 200 to 20000 pixels");
  }
  if (gnuplot.empty()) return fail("plot: no gnuplot program");
  return true;
}

std::string GnuplotNumber(double value) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  return buf;
}

std::string GnuplotSingleQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string GnuplotDoubleQuoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void WritePlotFile(const std::string& path, const std::string& text) {
  WriteFileAtomically(path, "plot data", text);
}

void RunGnuplot(const PictureOptions& options,
                const std::function<std::string(const std::string& dir,
                                                const std::string& staged_png)>& write_data) {
  const std::string& gnuplot = options.gnuplot;
  const std::string& work_dir = options.work_dir;
  const std::string& out_png = options.out_png;
  // gnuplot writes the picture to a temporary beside it, renamed into place once gnuplot
  // succeeded: a failed or interrupted plot leaves the old picture, or none.
  StagedFile png(out_png, "picture");
  std::string dir = work_dir;
  if (dir.empty()) {
    std::string pattern = std::filesystem::temp_directory_path().string() + "/plot-XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("plot: cannot create a temporary directory");
    }
    dir = pattern;
  } else {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
  }
  struct Cleanup {
    std::string dir;
    ~Cleanup() {
      if (!dir.empty()) std::filesystem::remove_all(dir);
    }
  } cleanup{work_dir.empty() ? dir : ""};

  WritePlotFile(dir + "/plot.gp", write_data(dir, png.temp_path()));
  // GnuplotSingleQuoted() is also the shell's quoting for text without single quotes; refuse the
  // rest rather than pass it to the shell.
  for (const std::string* s : std::initializer_list<const std::string*>{&gnuplot, &dir}) {
    if (s->find('\'') != std::string::npos) {
      throw std::invalid_argument("plot: quote characters in '" + *s + "' are not supported");
    }
  }
  const std::string errors = dir + "/gnuplot.err";
  const std::string command = GnuplotSingleQuoted(gnuplot) + " " +
                              GnuplotSingleQuoted(dir + "/plot.gp") + " 2> " +
                              GnuplotSingleQuoted(errors);
  const int status = std::system(command.c_str());
  std::ifstream err_in(errors);
  std::string message((std::istreambuf_iterator<char>(err_in)), std::istreambuf_iterator<char>());
  if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) == 127) {
    throw std::runtime_error("plot: cannot run '" + gnuplot +
                             "': is gnuplot installed? (Debian: apt-get install gnuplot-nox, "
                             "or scripts/setup.sh)");
  }
  if (WEXITSTATUS(status) != 0) {
    throw std::runtime_error("plot: gnuplot failed (exit " + std::to_string(WEXITSTATUS(status)) +
                             "): " + message);
  }
  if (std::filesystem::file_size(png.temp_path()) == 0) {
    throw std::runtime_error("plot: gnuplot wrote no " + out_png + ": " + message);
  }
  png.Commit();
}

}  // namespace slideid
