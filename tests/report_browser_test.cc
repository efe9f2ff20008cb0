// The HTML report in a real browser: Debian's chromium, headless, renders the report of the
// bundled default log, of a pooled synthetic run (make-dataset) and of validate on it, to a
// PNG and to a DOM dump. The DOM must hold every section and figure, and the browser's log
// must show no console message: the page's Content-Security-Policy forbids every load, so a
// resource the page tried to load shows there as a blocked load (a control page proves it).
// Skipped, saying so, only where chromium is not installed (scripts/setup.sh installs it).
// Also the --report option's own errors: usage, and a page that cannot be written.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "report/html_report.h"

namespace slideid {
namespace {

// A browser that has not finished by then is killed: the test must never hang.
constexpr int kBrowserTimeoutS = 120;
// A tool run (identify, make-dataset, validate) likewise.
constexpr int kToolTimeoutS = 600;

// Debian's chromium; SLIDEID_CHROMIUM names another (or none, to see the skip).
std::string Chromium() {
  const char* env = std::getenv("SLIDEID_CHROMIUM");
  return env ? env : "/usr/bin/chromium";
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Bin(const std::string& tool) {
  const char* env = std::getenv("SLIDEID_BIN_DIR");
  return std::string(env ? env : "build/bin") + "/" + tool;
}

// A fresh directory `prefix`XXXXXX ("" when it cannot be made).
std::string FreshDir(const std::string& prefix) {
  std::string dir = prefix + "XXXXXX";
  if (!mkdtemp(dir.data())) return "";
  return dir;
}

std::string MakeTempDir(const std::string& name) {
  return FreshDir(::testing::TempDir() + name + "_");
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

struct Rendered {
  int exit_code = -1;
  std::string dom;
  std::string log;  ///< the browser's stderr
  std::string png;  ///< the screenshot's bytes
};

// Renders `html` (a path) headless: the DOM dump, then a screenshot, each in a fresh profile.
Rendered Render(const std::string& html, const std::string& work) {
  const std::string flags = std::string("timeout ") + std::to_string(kBrowserTimeoutS) + " " +
                            Chromium() +
                            " --headless --no-sandbox --disable-gpu --no-first-run "
                            "--enable-logging=stderr --v=0 --user-data-dir=";
  // A profile of its own per run: two browsers on one profile refuse to start.
  const std::string dom_profile = FreshDir(work + "/profile_dom_");
  const std::string png_profile = FreshDir(work + "/profile_png_");
  Rendered r;
  if (dom_profile.empty() || png_profile.empty()) return r;
  r.exit_code = Shell(flags + dom_profile + " --dump-dom file://" + html + " > " + work +
                      "/dom.html 2> " + work + "/dom.log");
  r.dom = ReadText(work + "/dom.html");
  r.log = ReadText(work + "/dom.log");
  const int shot = Shell(flags + png_profile + " --window-size=1280,2000 --screenshot=" + work +
                         "/page.png file://" + html + " > /dev/null 2> " + work + "/png.log");
  if (r.exit_code == 0) r.exit_code = shot;
  r.log += ReadText(work + "/png.log");
  r.png = ReadText(work + "/page.png");
  Shell("rm -rf " + dom_profile + " " + png_profile);  // tens of MB each
  return r;
}

// The browser's lines that tell of the page: console messages (a blocked load is one), and
// failed loads. Its own complaints about the machine (no D-Bus, no GPU) are not the page's.
std::vector<std::string> PageTroubles(const std::string& log) {
  std::vector<std::string> out;
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);) {
    if (line.find(":CONSOLE") != std::string::npos || line.find("net::ERR_") != std::string::npos ||
        line.find("Failed to load") != std::string::npos) {
      out.push_back(line);
    }
  }
  return out;
}

bool HasChromium() { return access(Chromium().c_str(), X_OK) == 0; }

#define SKIP_WITHOUT_CHROMIUM()                                                               \
  if (!HasChromium()) {                                                                       \
    GTEST_SKIP() << "chromium is not installed (" << Chromium()                               \
                 << "): the report was not rendered in a browser; scripts/setup.sh installs " \
                    "it (apt-get install chromium)";                                          \
  }

void ExpectRenderedReport(const Rendered& r, int min_figures) {
  EXPECT_EQ(r.exit_code, 0) << r.log;
  for (const std::string& id : ReportSectionIds()) {
    EXPECT_NE(r.dom.find("<section id=\"" + id + "\">"), std::string::npos) << id;
  }
  EXPECT_GE(Count(r.dom, "<svg"), min_figures);
  EXPECT_GE(Count(r.dom, "<polyline"), min_figures);
  const std::vector<std::string> troubles = PageTroubles(r.log);
  EXPECT_TRUE(troubles.empty()) << "the browser said of the page: " << troubles.front();
  ASSERT_GT(r.png.size(), 8u);
  EXPECT_EQ(r.png.substr(1, 3), "PNG");
  // A blank page of this size compresses to a few kB; the report's text and figures do not.
  EXPECT_GT(r.png.size(), 20000u);
}

// ---- the --report option itself (no browser) ----

TEST(ReportTool, ReportWithCheckBatchOrFollowIsAUsageError) {
  const std::string work = MakeTempDir("report_usage");
  ASSERT_FALSE(work.empty());
  const std::string log = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  for (const std::string& args : std::vector<std::string>{
           "--check --log " + log, "--batch " + log + " --out " + work + "/r.jsonl", "--follow"}) {
    EXPECT_EQ(Shell(Bin("identify") + " " + args + " --report " + work +
                    "/r.html < /dev/null > /dev/null 2>&1"),
              2)
        << args;
  }
  EXPECT_NE(access((work + "/r.html").c_str(), F_OK), 0);
}

TEST(ReportTool, AReportThatCannotBeWrittenExitsFourAndLeavesNoFile) {
  const std::string work = MakeTempDir("report_unwritable");
  ASSERT_FALSE(work.empty());
  const std::string out = work + "/no_such_directory/report.html";
  EXPECT_EQ(
      Shell(Bin("identify") + " --log " + SLIDEID_SOURCE_DIR +
            "/datasets/logs/default_push.csv --report " + out + " > " + work + "/out.txt 2>&1"),
      4);
  EXPECT_NE(ReadText(work + "/out.txt").find("cannot write the HTML report"), std::string::npos)
      << ReadText(work + "/out.txt");
  EXPECT_NE(access(out.c_str(), F_OK), 0);
}

// ---- in the browser ----

TEST(ReportBrowser, ControlPageThatLoadsSomethingIsCaught) {
  SKIP_WITHOUT_CHROMIUM();
  const std::string work = MakeTempDir("report_control");
  ASSERT_FALSE(work.empty());
  // The same policy as the report's: the loads are blocked before any request is made.
  std::ofstream(work + "/bad.html")
      << "<!DOCTYPE html><html><head><meta http-equiv=\"Content-Security-Policy\" "
         "content=\"default-src 'none'; style-src 'unsafe-inline'; img-src data:\"></head>"
         "<body><img src=\"http://127.0.0.1:9/x.png\"></body></html>";
  const Rendered r = Render(work + "/bad.html", work);
  EXPECT_EQ(r.exit_code, 0) << r.log;
  EXPECT_FALSE(PageTroubles(r.log).empty()) << "a blocked load went unseen:\n" << r.log;
}

TEST(ReportBrowser, DefaultLogReportRendersWithEverySectionAndNothingLoaded) {
  SKIP_WITHOUT_CHROMIUM();
  const std::string work = MakeTempDir("report_default");
  ASSERT_FALSE(work.empty());
  const std::string report = work + "/report.html";
  ASSERT_EQ(Shell("timeout " + std::to_string(kToolTimeoutS) + " " + Bin("identify") + " --log " +
                  SLIDEID_SOURCE_DIR + "/datasets/logs/default_push.csv --report " + report +
                  " > " + work + "/identify.txt 2>&1"),
            0)
      << ReadText(work + "/identify.txt");
  const Rendered r = Render(report, work);
  // The trace, and the log's path and residuals.
  ExpectRenderedReport(r, 3);
  EXPECT_NE(r.dom.find("default_push.csv"), std::string::npos);
  EXPECT_NE(r.dom.find("Ceres cost per iteration"), std::string::npos);
}

TEST(ReportBrowser, PooledSyntheticRunAndItsValidationRender) {
  SKIP_WITHOUT_CHROMIUM();
  const std::string work = MakeTempDir("report_pooled");
  ASSERT_FALSE(work.empty());
  const std::string timeout = "timeout " + std::to_string(kToolTimeoutS) + " ";
  ASSERT_EQ(Shell(timeout + Bin("make-dataset") +
                  " --count 3 --pushes 2 --seed 11 --quiet --noise-pose 3e-4 "
                  "--noise-force-relative 0.02 --out " +
                  work + "/logs > " + work + "/make.txt 2>&1"),
            0)
      << ReadText(work + "/make.txt");
  ASSERT_EQ(Shell(timeout + Bin("identify") + " --logs " + work + "/logs --report " + work +
                  "/pooled.html > " + work + "/identify.txt 2>&1"),
            0)
      << ReadText(work + "/identify.txt");
  const Rendered pooled = Render(work + "/pooled.html", work);
  // 3 forest plots, the trace, and a path and residuals per log.
  ExpectRenderedReport(pooled, 3 + 1 + 2 * 3);
  EXPECT_NE(pooled.dom.find("forest plot of e_t_mu"), std::string::npos);
  EXPECT_NE(pooled.dom.find("Cochran"), std::string::npos);

  ASSERT_EQ(Shell(timeout + Bin("validate") + " --logs " + work + "/logs --report " + work +
                  "/validate.html > " + work + "/validate.txt 2>&1"),
            0)
      << ReadText(work + "/validate.txt");
  const Rendered validated = Render(work + "/validate.html", work);
  // Per log: the predicted path and its error against time.
  ExpectRenderedReport(validated, 2 * 3);
  EXPECT_NE(validated.dom.find("prediction error against time"), std::string::npos);
}

}  // namespace
}  // namespace slideid
