// The HTML report (report/): the SVG writer, escaping, every section present, nothing
// loaded from anywhere, no "nan" printed; the import report row; and the report of the
// bundled default log gathered through the pipeline as identify --report gathers it.

#include "report/html_report.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

#include "estimator/log_check.h"
#include "io/import_report_row.h"
#include "pipeline/identify_files.h"
#include "pipeline/report_files.h"
#include "report/html_text.h"
#include "report/svg_plot.h"
#include "tests/estimator_test_support.h"

namespace slideid {
namespace {

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// What makes a page self-contained: no URL with a scheme, no src attribute, every link an
// anchor in the page, no script, and the policy that forbids loading anything.
void ExpectSelfContained(const std::string& html) {
  EXPECT_EQ(html.find("://"), std::string::npos) << "a URL in the page";
  EXPECT_EQ(html.find("src="), std::string::npos) << "something to load";
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("url("), std::string::npos) << "a CSS url()";
  EXPECT_EQ(html.find("@import"), std::string::npos);
  const std::regex href("href=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), href); it != std::sregex_iterator();
       ++it) {
    EXPECT_EQ((*it)[1].str().rfind('#', 0), 0u) << "a link out of the page: " << (*it)[0].str();
  }
  EXPECT_NE(html.find("Content-Security-Policy\" content=\"default-src 'none'"), std::string::npos);
}

// No number printed as nan or inf (as a word: "information" and "infinite" are words).
void ExpectNoNan(const std::string& html) {
  const std::regex bad("[^A-Za-z](nan|NaN|inf|-inf)[^A-Za-z]");
  std::smatch m;
  EXPECT_FALSE(std::regex_search(html, m, bad)) << "printed: '" << m.str() << "'";
}

TEST(HtmlText, EscapesEveryCharacterThatCouldEndTextOrAnAttribute) {
  EXPECT_EQ(HtmlEscape("<a href=\"x\">Tom & 'Jerry'</a>"),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;");
  EXPECT_EQ(HtmlEscape("plain"), "plain");
}

TEST(HtmlText, NumbersThatAreNotFiniteReadAsADash) {
  EXPECT_EQ(HtmlNumber(std::nan("")), "—");
  EXPECT_EQ(HtmlNumber(INFINITY, 4, "not identifiable"), "not identifiable");
  EXPECT_EQ(HtmlNumber(0.123456, 3), "0.123");
}

TEST(SvgPlot, ALineBrokenByANonFinitePointIsTwoPolylines) {
  SvgPlot plot(400, 300);
  plot.SetTitle("t <1>");
  plot.AddLine({0, 1, 2, 3, 4}, {0, 1, std::nan(""), 3, 4}, {}, "a & b");
  const std::string svg = plot.Render("label \"quoted\"");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(Count(svg, "<polyline"), 2);
  EXPECT_NE(svg.find("aria-label=\"label &quot;quoted&quot;\""), std::string::npos);
  EXPECT_NE(svg.find("t &lt;1&gt;"), std::string::npos);
  EXPECT_NE(svg.find("a &amp; b"), std::string::npos);
  ExpectSelfContained(
      svg + "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'\">");
  ExpectNoNan(svg);
}

TEST(SvgPlot, LongLinesAreThinnedAndKeepTheirLastPoint) {
  std::vector<double> x, y;
  for (int k = 0; k < 10 * kMaxLinePoints; ++k) {
    x.push_back(k);
    y.push_back(std::sin(k * 1e-3));
  }
  SvgPlot plot(400, 300);
  plot.AddLine(x, y, {});
  const std::string svg = plot.Render("long");
  const size_t points = svg.find("points=\"");
  ASSERT_NE(points, std::string::npos);
  const std::string list = svg.substr(points, svg.find('"', points + 8) - points);
  EXPECT_LE(Count(list, ","), kMaxLinePoints + 1);
  EXPECT_GE(Count(list, ","), kMaxLinePoints / 2);
}

TEST(SvgPlot, LogScaleLeavesOutValuesThatAreNotPositive) {
  SvgPlot plot(400, 300);
  plot.SetLogY(true);
  plot.AddMarkers({0, 1, 2}, {1e-3, 0.0, 10.0}, {});
  const std::string svg = plot.Render("log");
  EXPECT_EQ(Count(svg, "<circle"), 2);
  EXPECT_NE(svg.find(">1e-3<"), std::string::npos);
  ExpectNoNan(svg);
}

// A report made up in memory: a pooled fit of two logs, one parameter not identifiable,
// a log whose name would be markup, a trace and correlations.
ReportInputs MadeUpInputs() {
  ReportInputs in;
  in.tool = "identify";
  in.version = "9.9.9";
  in.command_line = "identify --log '<b>odd</b>.csv' --report r.html";
  in.timings = {{"everything", 1.25}};
  EstimateResult r;
  r.status = TerminationStatus::kConvergedWithCaveats;
  for (int i = 0; i < 2; ++i) {
    ParameterEstimate& p = r.parameters[i];
    p.identifiable = true;
    p.verdict = i == 0 ? Verdict::kOk : Verdict::kSuspect;
    p.value = 0.4 + i;
    p.stderr_value = 0.01;
    p.ci95_lo = p.value - 0.02;
    p.ci95_hi = p.value + 0.02;
    p.reason = i == 1 ? "residuals > noise & <worse>" : "";
  }
  r.parameters[2].reason = "every push passes within 0 mm of the CM";
  r.parameters[2].held_at = 0.03;
  r.correlation = NaNCorrelation();
  r.correlation[0][0] = r.correlation[1][1] = 1;
  r.correlation[0][1] = r.correlation[1][0] = -0.7;
  for (int k = 0; k < 5; ++k) r.trace.push_back({"least squares", k, 10.0 / (1 + k), 0, 0});
  for (int k = 0; k < 3; ++k) r.trace.push_back({"robust", k, 1.0 / (1 + k), 0, 0});
  r.residual_names = {"x_m", "y_m", "theta_times_L_m"};
  for (int k = 0; k < 20; ++k) r.residuals.push_back({k % 2, k, 0.01 * k, {1e-4, -1e-4, 0}, true});
  for (const char* name : {"<b>odd</b>.csv", "b.csv"}) {
    LogResult l;
    l.name = name;
    l.parameters = r.parameters;
    r.logs.push_back(l);
  }
  r.heterogeneity[0] = {true, 2, 0.5, 0.48, 0.0, 0.0, true};
  in.result = r;
  in.truth = ReducedFriction{0.4, 1.4, 0.03};
  for (const char* name : {"<b>odd</b>.csv", "b.csv"}) {
    ReportLog l;
    l.name = name;
    l.path = std::string("dir/") + name;
    l.fit_index = static_cast<int>(in.logs.size());
    l.log.patch = ContactPatch::Rectangle(0.1, 0.08);
    for (int k = 0; k < 10; ++k) {
      TrajectorySample s;
      s.t_s = 0.1 * k;
      s.state.x = 0.01 * k;
      s.state.theta = 0.05 * k;
      l.log.samples.push_back(s);
    }
    l.replay = l.log;
    LogCheck c;
    c.name = name;
    c.advice = {"push off-centre & turn the object"};
    c.condition_number = INFINITY;
    l.check = c;
    l.import_row = {{"source", "push <1>.json"}, {"offset_drift_n", ""}};
    l.import_report_path = "dir/import_report.csv";
    in.logs.push_back(l);
  }
  in.warnings = {"a warning with <markup>"};
  return in;
}

TEST(HtmlReport, HasEverySectionAndFigureAndEscapesWhatItQuotes) {
  const std::string html = RenderHtmlReport(MadeUpInputs());
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  for (const std::string& id : ReportSectionIds()) {
    EXPECT_EQ(Count(html, "<section id=\"" + id + "\">"), 1) << id;
  }
  // 3 forest plots, 1 trace, per log a path and a residual figure.
  EXPECT_EQ(Count(html, "<svg"), 3 + 1 + 2 * 2);
  EXPECT_EQ(html.find("<b>"), std::string::npos) << "a log's name was put in as markup";
  EXPECT_NE(html.find("&lt;b&gt;odd&lt;/b&gt;.csv"), std::string::npos);
  EXPECT_NE(html.find("a warning with &lt;markup&gt;"), std::string::npos);
  EXPECT_NE(html.find("push off-centre &amp; turn the object"), std::string::npos);
  EXPECT_NE(html.find("not identifiable"), std::string::npos);
  EXPECT_NE(html.find("-0.700"), std::string::npos);  // the correlation of a and b
  EXPECT_NE(html.find("slideid 9.9.9"), std::string::npos);
  EXPECT_NE(html.find("push &lt;1&gt;.json"), std::string::npos);  // the import row
  ExpectSelfContained(html);
  ExpectNoNan(html);
}

TEST(HtmlReport, ValidateReportShowsPredictionsAndSaysWhatItLacks) {
  ReportInputs in = MadeUpInputs();
  in.tool = "validate";
  in.result.reset();
  ValidationResult v;
  v.logs = {"<b>odd</b>.csv", "b.csv"};
  v.folds = 2;
  FoldFit f;
  f.ok = true;
  f.held_out = {"b.csv"};
  v.fold_fits = {f};
  MethodValidation m;
  m.method = "folds";
  PushPrediction p;
  p.log = "dir/b.csv";
  p.ok = true;
  p.errors.final_position_m = 0.002;
  m.pushes = {p};
  m.final_position_m = {1, 0.002, 0.002, 0.002, 0.002};
  v.methods = {m};
  in.validation = v;
  for (ReportLog& l : in.logs) {
    l.prediction = l.log;
    l.replay.reset();
  }
  const std::string html = RenderHtmlReport(in);
  for (const std::string& id : ReportSectionIds()) {
    EXPECT_EQ(Count(html, "<section id=\"" + id + "\">"), 1) << id;
  }
  EXPECT_NE(html.find("prediction error against time"), std::string::npos);
  EXPECT_NE(html.find("validate fits each fold"), std::string::npos);
  EXPECT_EQ(Count(html, "<svg"), 2 * 2);
  ExpectSelfContained(html);
  ExpectNoNan(html);
}

TEST(ImportReportRow, FindsTheLogsRowByItsFileNameWithQuotedCells) {
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/import_report_row_test.csv";
  {
    std::ofstream out(path);
    out << "source,object,verdict,reason,output,rows\n"
        << "a.json,rect1,rejected,\"too short, by far\",,0\n"
        << "\"b \"\"x\"\".json\",rect1,accepted,,/somewhere/else/b.csv,120\n";
  }
  const auto row = FindImportReportRow(path, "b.csv");
  ASSERT_EQ(row.size(), 6u);
  EXPECT_EQ(row[0], (std::pair<std::string, std::string>{"source", "b \"x\".json"}));
  EXPECT_EQ(row[5].second, "120");
  EXPECT_TRUE(FindImportReportRow(path, "c.csv").empty());
  EXPECT_TRUE(FindImportReportRow(dir + "/no_such_report.csv", "b.csv").empty());
  EXPECT_EQ(ImportReportBeside("/data/logs/b.csv"), "/data/logs/import_report.csv");
}

TEST(ReportFiles, CommandLineIsQuotedAsAShellWouldReadIt) {
  const char* argv[] = {"identify", "--log", "my log.csv", "--report", "it's.html"};
  EXPECT_EQ(QuotedCommandLine(5, argv), "identify --log 'my log.csv' --report 'it'\\''s.html'");
}

// The bundled log through the pipeline: what identify --report writes, without the tool.
TEST(ReportFiles, DefaultLogReportHasItsTraceCorrelationsReplayAndCheck) {
  const std::string log = std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv";
  const FileIdentifyOptions options;
  const FileIdentifyResult run = IdentifyFiles({log}, options);
  const EstimateResult& r = run.result;
  ASSERT_FALSE(r.trace.empty());
  EXPECT_EQ(r.trace.front().iteration, 0);
  // The trace counts every solve's iterations, as `iterations` does.
  EXPECT_EQ(static_cast<int>(r.trace.size()), r.iterations);
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(r.parameters[i].identifiable);
    EXPECT_NEAR(r.correlation[i][i], 1.0, 1e-12);
    for (int j = 0; j < 3; ++j) {
      EXPECT_LE(std::abs(r.correlation[i][j]), 1.0 + 1e-12);
      EXPECT_DOUBLE_EQ(r.correlation[i][j], r.correlation[j][i]);
    }
  }
  ReportInputs in = GatherIdentifyReport({log}, options, run);
  ASSERT_EQ(in.logs.size(), 1u);
  EXPECT_TRUE(in.logs[0].check.has_value()) << in.logs[0].check_note;
  ASSERT_TRUE(in.logs[0].replay.has_value()) << in.logs[0].replay_note;
  EXPECT_EQ(in.logs[0].replay->samples.size(), in.logs[0].log.samples.size());
  EXPECT_EQ(in.logs[0].fit_index, 0);
  EXPECT_TRUE(in.logs[0].import_row.empty());
  const std::string html = RenderHtmlReport(in);
  EXPECT_NE(html.find("Ceres cost per iteration"), std::string::npos);
  EXPECT_NE(html.find("residuals against time"), std::string::npos);
  EXPECT_NE(html.find("One log: nothing was pooled."), std::string::npos);
  ExpectSelfContained(html);
  ExpectNoNan(html);
}

// A log that import-log wrote sits beside its import_report.csv: the report shows its row.
TEST(ReportFiles, LogBesideAnImportReportShowsItsRow) {
  std::string dir = ::testing::TempDir() + "report_import_XXXXXX";
  ASSERT_NE(mkdtemp(dir.data()), nullptr);
  const std::string log = dir + "/push_7.csv";
  {
    std::ifstream in(std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv");
    std::ofstream out(log);
    out << in.rdbuf();
    std::ofstream report(dir + "/import_report.csv");
    report << "source,object,verdict,reason,output,rows\n"
           << "push_6.json,rect1,accepted,,out/push_6.csv,10\n"
           << "push_7.json,rect1,accepted,,out/push_7.csv,601\n";
  }
  FileIdentifyOptions options;
  const FileIdentifyResult run = IdentifyFiles({log}, options);
  const ReportInputs in = GatherIdentifyReport({log}, options, run);
  ASSERT_EQ(in.logs.size(), 1u);
  ASSERT_EQ(in.logs[0].import_row.size(), 6u);
  EXPECT_EQ(in.logs[0].import_row[0].second, "push_7.json");
  EXPECT_NE(RenderHtmlReport(in).find("push_7.json"), std::string::npos);
}

// A log from a pipe (identify --log <(zcat log.csv.gz) --report r.html) is read once: the
// report draws the logs the fit read (FileIdentifyOptions::keep_logs). It read them again,
// got nothing from the spent pipe, and left the log out of the page without a word.
TEST(ReportFiles, ALogFromAPipeIsInTheReport) {
  const std::string fifo = testing::TempPath("report_pipe.csv");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::atomic<bool> done{false};
  std::thread writer([&] {
    {
      std::ifstream in(std::string(SLIDEID_SOURCE_DIR) + "/datasets/logs/default_push.csv");
      std::ofstream(fifo) << in.rdbuf();
    }
    // A second reader of the spent pipe gets an end of file, not a wait for ever: a
    // writer that comes and goes (opening without a reader fails, ENXIO, and is retried).
    while (!done) {
      const int fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) close(fd);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  const std::string html = testing::TempPath("report_pipe.html");
  const testing::ToolRun run =
      testing::RunTool("identify", "--log " + fifo + " --method closed-form --report " + html);
  done = true;
  writer.join();
  // The closed form identifies nothing on the bundled log's noisy poses (exit 1); the report
  // is written whatever the fit's outcome.
  EXPECT_EQ(run.code, 1) << run.err;
  EXPECT_NE(run.err.find("no friction parameter is identifiable"), std::string::npos) << run.err;
  const std::string page = testing::ReadText(html);
  EXPECT_NE(page.find("path of the CM"), std::string::npos) << page.substr(0, 2000);
  EXPECT_NE(page.find("report_pipe.csv"), std::string::npos);
}

}  // namespace
}  // namespace slideid
