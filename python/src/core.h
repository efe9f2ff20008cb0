#pragma once
// What the parts of slideid._core share: the Python objects behind a Log, the errors that
// become Python exceptions, and the reading of keyword arguments as command-line options.
// The module is thin like a tool: it converts Python values, calls one library function,
// and converts the result back.

#include <pybind11/pybind11.h>

#include <boost/program_options.hpp>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/push_log.h"

namespace slideid::python {

namespace py = pybind11;

/// A fit or a simulation that did not converge, or a slider that would tip (the tools' exit
/// code 3): slideid.NumericalError.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A file that could not be written (the tools' exit code 4): OSError.
class WriteFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A push log in memory and what its reader said: the object behind slideid.Log.
struct LogHandle {
  PushLogFile file;  ///< the log and what its file says beyond it (metadata, patch text)
  std::vector<std::string> warnings;  ///< likely mistakes, each naming its file and line
  std::vector<std::string> notes;     ///< plain facts
};
using LogPtr = std::shared_ptr<LogHandle>;

/// Reads a call's keyword arguments as `description`'s command-line options are read, so
/// that values are checked, and bad ones named, as on the command line: keyword x_y is option
/// --x-y. True gives a switch, or an option whose value may be left out (--fit-delay);
/// False and None leave an option out; True and False for an option that needs a value give
/// "yes" and "no"; a list or tuple repeats the option; any other value is given as
/// str(value). `leading` arguments ("--out=DIR") go first. Throws py::type_error naming
/// `function` for a keyword that is no option, or one of `reserved`;
/// boost::program_options::error for bad values.
boost::program_options::variables_map ParseKeywords(
    const std::string& function, const boost::program_options::options_description& description,
    const py::dict& keywords, const std::vector<std::string>& reserved = {},
    const std::vector<std::string>& leading = {});

void RegisterExceptions(py::module_& m);  ///< NumericalError, OptionError, translations
void BindLog(py::module_& m);             ///< Log, read_log, make_log, write_log
void BindIdentify(py::module_& m);        ///< identify
void BindSimulate(py::module_& m);        ///< simulate, make_dataset
void BindImport(py::module_& m);          ///< import_log
void BindPredict(py::module_& m);         ///< predict, validate
void BindOnline(py::module_& m);          ///< OnlineCore (slideid.OnlineIdentifier)
void BindAdvise(py::module_& m);          ///< advise_push

}  // namespace slideid::python
