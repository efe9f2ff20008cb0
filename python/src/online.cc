// OnlineIdentifier: the online identifier (estimator/online_identifier.h) fed rows from
// numpy arrays; each row read as the log reader reads a row of a file, each result the JSON
// line of identify --follow (io/online_json.h), which the Python layer turns into a dict.

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <optional>

#include "core.h"
#include "estimator/online_identifier.h"
#include "io/online_json.h"
#include "io/push_log.h"

namespace slideid::python {
namespace {

constexpr double kTwoPi = 6.283185307179586;

class OnlineCore {
 public:
  OnlineCore(std::vector<std::pair<std::string, std::string>> metadata,
             std::vector<std::string> columns, int batch_check_rows)
      : metadata_(std::move(metadata)), columns_(std::move(columns)) {
    OnlineOptions options;
    options.batch_check_first_rows = batch_check_rows;  // checked by the identifier
    // The metadata read as a file's would be, with one row to carry it.
    PushLogColumns table;
    table.names = columns_;
    table.values.assign(columns_.size(), std::vector<double>{0.0});
    identifier_ = std::make_unique<OnlineIdentifier>(
        ParsePushLogColumns(table, metadata_, kSource, ReadOptions()).log, options);
  }

  /// Rows (n x columns), in order: one JSON line per row.
  std::vector<std::string> UpdateMany(
      const py::array_t<double, py::array::c_style | py::array::forcecast>& rows) {
    if (rows.ndim() != 2 || rows.shape(1) != static_cast<py::ssize_t>(columns_.size())) {
      throw std::invalid_argument("OnlineIdentifier: rows must be an array of shape (n, " +
                                  std::to_string(columns_.size()) + ") in the columns' order");
    }
    PushLogColumns table;
    table.names = columns_;
    table.values.assign(columns_.size(), std::vector<double>(rows.shape(0)));
    for (py::ssize_t i = 0; i < rows.shape(0); ++i)
      for (size_t j = 0; j < columns_.size(); ++j) table.values[j][i] = rows.at(i, j);
    std::vector<std::string> out;
    out.reserve(rows.shape(0));
    py::gil_scoped_release release;
    if (rows.shape(0) == 0) return out;
    const Trajectory chunk = ParsePushLogColumns(table, metadata_, kSource, ReadOptions()).log;
    for (const TrajectorySample& read : chunk.samples) {
      TrajectorySample row = read;
      // A chunk's first row reads as a run's first; after the first chunk it is not.
      if (&read == &chunk.samples.front() && identifier_->result().rows > 0) {
        row.mode = SampleMode::kSlide;
      }
      if (previous_theta_) {
        row.state.theta += kTwoPi * std::round((*previous_theta_ - row.state.theta) / kTwoPi);
      }
      previous_theta_ = row.state.theta;
      out.push_back(FormatOnlineJson(identifier_->Update(row)));
    }
    return out;
  }

 private:
  static constexpr const char* kSource = "OnlineIdentifier";
  static LogReadOptions ReadOptions() {
    LogReadOptions o;
    o.max_gap_ratio = 0;  // rows come in chunks: no median interval to hold a gap against
    return o;
  }
  std::vector<std::pair<std::string, std::string>> metadata_;
  std::vector<std::string> columns_;
  std::unique_ptr<OnlineIdentifier> identifier_;
  std::optional<double> previous_theta_;
};

}  // namespace

void BindOnline(py::module_& m) {
  py::class_<OnlineCore>(m, "OnlineCore", "the online identifier behind slideid.OnlineIdentifier")
      .def(py::init<std::vector<std::pair<std::string, std::string>>, std::vector<std::string>,
                    int>(),
           py::arg("metadata"), py::arg("columns"), py::arg("batch_check_rows"))
      .def("update_many", &OnlineCore::UpdateMany, py::arg("rows"),
           "rows (n x columns): one JSON line per row; the GIL is released while it runs");
}

}  // namespace slideid::python
