#pragma once
// The HTML report of identify --report and validate --report (docs/identify.md, "The HTML
// report"): one self-contained page, its figures inline SVG (report/svg_plot.h), its style
// inline, a Content-Security-Policy that forbids loading anything, and no script.
//
// Sections (each a <section> with this id; those that do not apply say so in a line):
//   summary      the status in words
//   estimates    a, b, c (and mu_p, the nuisances) with intervals and verdicts; validate:
//                each fold's friction
//   pooled       pooled fits: the forest plot of each parameter and the heterogeneity
//   predictions  validate: each method's errors over the pushes
//   logs         per log: the logged and replayed (or predicted) path with the contact
//                patch at a few poses and the tip's path, the residuals against time
//                (validate: the prediction's error against time), its import report row
//   check        the check before fitting, per log (estimator/log_check.h)
//   correlation  the correlations of a, b, c from the fit's covariance
//   trace        the optimisation trace: Ceres' cost per iteration of each solve
//   run          the command line, the version, the timings, the warnings

#include <string>
#include <vector>

#include "report/report_inputs.h"

namespace slideid {

/// The report as one HTML document.
std::string RenderHtmlReport(const ReportInputs& inputs);

/// The ids of the sections every report has, in order.
const std::vector<std::string>& ReportSectionIds();

}  // namespace slideid
