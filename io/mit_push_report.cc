#include "io/mit_push_report.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <utility>

#include "forward_model/constants.h"
#include "forward_model/number_format.h"
#include "io/atomic_file.h"

namespace slideid {
namespace {

/// Six significant digits: the report's precision.
std::string Number(double value) { return Printf("%.6g", value); }

std::string Number(const std::optional<double>& value, double scale = 1.0) {
  return value ? Number(*value * scale) : "";
}

/// RFC 4180 quoting where needed.
std::string Text(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) {
    if (c == '"') out += '"';
    out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out + "\"";
}

using Cell = std::function<std::string(const MitImportReport&)>;

/// Whether the streams were examined (not for an unreadable file or an unknown object):
/// counts of a file never examined are unknown, not zero.
bool Examined(const MitImportReport& r) { return r.ft_wrench.cleanup.rows_in > 0; }

/// A count, empty when the file was not examined.
std::string Count(const MitImportReport& r, int value) {
  return Examined(r) ? std::to_string(value) : "";
}

void AddStream(std::vector<std::pair<std::string, Cell>>* columns, const std::string& name,
               StreamSummary MitImportReport::*stream) {
  columns->push_back({name + "_rows_in", [=](const MitImportReport& r) {
                        return Count(r, (r.*stream).cleanup.rows_in);
                      }});
  columns->push_back({name + "_backward_steps", [=](const MitImportReport& r) {
                        return Count(r, (r.*stream).cleanup.backward_steps);
                      }});
  columns->push_back({name + "_duplicates_dropped", [=](const MitImportReport& r) {
                        return Count(r, (r.*stream).cleanup.duplicates_dropped);
                      }});
  columns->push_back({name + "_rate_hz", [=](const MitImportReport& r) {
                        return Examined(r) ? Number((r.*stream).median_rate_hz) : "";
                      }});
  columns->push_back({name + "_largest_gap_ms", [=](const MitImportReport& r) {
                        return Examined(r) ? Number((r.*stream).largest_gap_s * 1e3) : "";
                      }});
}

const std::vector<std::pair<std::string, Cell>>& Columns() {
  static const std::vector<std::pair<std::string, Cell>> columns = [] {
    std::vector<std::pair<std::string, Cell>> c;
    using R = const MitImportReport&;
    c.push_back({"source", [](R r) { return Text(r.source); }});
    c.push_back({"object", [](R r) { return Text(r.object); }});
    c.push_back({"verdict", [](R r) { return std::string(ToString(r.verdict)); }});
    c.push_back({"reason", [](R r) { return Text(r.reason); }});
    c.push_back({"output", [](R r) { return Text(r.output); }});
    AddStream(&c, "object_pose", &MitImportReport::object_pose);
    AddStream(&c, "tip_pose", &MitImportReport::tip_pose);
    AddStream(&c, "ft_wrench", &MitImportReport::ft_wrench);
    c.push_back({"frozen_force_samples", [](R r) { return Count(r, r.frozen_force_samples); }});
    c.push_back({"pose_glitches_dropped", [](R r) { return Count(r, r.pose_glitches); }});
    c.push_back({"theta_wraps", [](R r) { return Count(r, r.theta_wraps); }});
    c.push_back({"theta_jumps_repaired", [](R r) { return Count(r, r.theta_jumps_repaired); }});
    c.push_back({"theta_jumps_unrepaired", [](R r) { return Count(r, r.theta_jumps_unrepaired); }});
    c.push_back({"largest_theta_step_deg", [](R r) {
                   return Examined(r) ? Number(r.largest_theta_step_rad * kRadToDeg) : "";
                 }});
    c.push_back({"largest_pose_gap_in_window_ms", [](R r) {
                   return r.rows > 0 ? Number(r.largest_pose_gap_in_window_s * 1e3) : "";
                 }});
    c.push_back({"pose_gaps_split",
                 [](R r) { return r.rows > 0 ? std::to_string(r.pose_gaps_split) : ""; }});
    c.push_back({"rows_dropped_in_pose_gaps", [](R r) {
                   return r.rows > 0 ? std::to_string(r.rows_dropped_in_pose_gaps) : "";
                 }});
    c.push_back({"offset_before_fx_n",
                 [](R r) { return r.offset_before_n ? Number(r.offset_before_n->x()) : ""; }});
    c.push_back({"offset_before_fy_n",
                 [](R r) { return r.offset_before_n ? Number(r.offset_before_n->y()) : ""; }});
    c.push_back({"offset_before_samples", [](R r) { return Count(r, r.offset_before_samples); }});
    c.push_back({"offset_after_fx_n",
                 [](R r) { return r.offset_after_n ? Number(r.offset_after_n->x()) : ""; }});
    c.push_back({"offset_after_fy_n",
                 [](R r) { return r.offset_after_n ? Number(r.offset_after_n->y()) : ""; }});
    c.push_back({"offset_after_samples", [](R r) { return Count(r, r.offset_after_samples); }});
    c.push_back({"offset_drift_n", [](R r) { return Number(r.offset_drift_n); }});
    c.push_back({"preload_n", [](R r) { return r.preload_n ? Number(r.preload_n->norm()) : ""; }});
    c.push_back({"force_noise_n",
                 [](R r) { return r.force_threshold_n > 0 ? Number(r.force_noise_n) : ""; }});
    c.push_back({"force_threshold_n",
                 [](R r) { return r.force_threshold_n > 0 ? Number(r.force_threshold_n) : ""; }});
    c.push_back({"normal_alignment", [](R r) { return Number(r.normal_alignment); }});
    c.push_back({"velocity_correlation", [](R r) { return Number(r.velocity_correlation); }});
    c.push_back({"force_flipped", [](R r) {
                   return r.normal_alignment ? std::string(r.force_flipped ? "yes" : "no") : "";
                 }});
    c.push_back({"contact_gap_median_mm", [](R r) { return Number(r.contact_gap_median_m, 1e3); }});
    c.push_back({"contact_gap_p05_mm", [](R r) { return Number(r.contact_gap_p05_m, 1e3); }});
    c.push_back({"contact_gap_p95_mm", [](R r) { return Number(r.contact_gap_p95_m, 1e3); }});
    c.push_back({"rows_out_of_contact_fraction",
                 [](R r) { return r.rows > 0 ? Number(r.rows_out_of_contact_fraction) : ""; }});
    c.push_back({"rows", [](R r) { return std::to_string(r.rows); }});
    c.push_back({"window_s", [](R r) { return r.rows > 0 ? Number(r.window_end_s) : ""; }});
    c.push_back({"peak_force_n", [](R r) { return r.rows > 0 ? Number(r.peak_force_n) : ""; }});
    c.push_back({"time_origin_unix_s",
                 [](R r) { return r.rows == 0 ? std::string() : ExactNumber(r.time_origin_s); }});
    c.push_back({"notes", [](R r) {
                   std::string all;
                   for (const std::string& note : r.notes) all += (all.empty() ? "" : "; ") + note;
                   return Text(all);
                 }});
    return c;
  }();
  return columns;
}

}  // namespace

std::string MitImportReportHeader() {
  std::string line;
  for (const auto& [name, cell] : Columns()) line += (line.empty() ? "" : ",") + name;
  return line;
}

std::string MitImportReportRow(const MitImportReport& report) {
  std::string line;
  bool first = true;
  for (const auto& [name, cell] : Columns()) {
    line += (first ? "" : ",") + cell(report);
    first = false;
  }
  return line;
}

void WriteMitImportReport(const std::vector<MitImportReport>& reports, const std::string& path) {
  WriteFileAtomically(path, "the import report", [&](std::ostream& out) {
    out << MitImportReportHeader() << '\n';
    for (const MitImportReport& r : reports) out << MitImportReportRow(r) << '\n';
  });
}

}  // namespace slideid
