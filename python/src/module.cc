// slideid._core: the compiled part of the slideid Python package (python/slideid/). Errors
// become Python exceptions as the tools' errors become exit codes: bad input ValueError
// (the tools' messages), a numerical failure slideid.NumericalError, a file that cannot be
// written OSError; a bad input never ends the interpreter.

#include <algorithm>
#include <new>
#include <regex>

#include "core.h"
#include "estimator/ceres_logging.h"

namespace slideid::python {
namespace {

// The Python types of the exceptions below; set once, when the module is imported.
PyObject* numerical_error_type = nullptr;
PyObject* option_error_type = nullptr;
PyObject* input_error_type = nullptr;

/// A message about options as Python keywords: the tools' "--fit-delay" is fit_delay here.
std::string AsKeywords(const std::string& message) {
  static const std::regex option("--([A-Za-z][A-Za-z0-9]*(-[A-Za-z0-9]+)*)");
  std::string out;
  auto last = message.cbegin();
  for (std::sregex_iterator it(message.begin(), message.end(), option), end; it != end; ++it) {
    out.append(last, (*it)[0].first);
    std::string name = (*it)[1].str();
    std::replace(name.begin(), name.end(), '-', '_');
    out += name;
    last = (*it)[0].second;
  }
  return out.append(last, message.cend());
}

void TranslateExceptions() {
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const py::error_already_set&) {
      throw;
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (type_error, ...)
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError
    } catch (const NumericalError& e) {
      PyErr_SetString(numerical_error_type, e.what());
    } catch (const boost::program_options::error& e) {
      // Named as the caller named it (substeps, not --substeps); the tools' own words stay
      // on the error as cli_message, for command lines built on the module (slideid.dask).
      py::object error =
          py::reinterpret_borrow<py::object>(option_error_type)(AsKeywords(e.what()));
      error.attr("cli_message") = std::string(e.what());
      PyErr_SetObject(option_error_type, error.ptr());
    } catch (const WriteFailure& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const std::exception& e) {
      // LogError, SceneError, FileError, option errors, std::invalid_argument, ...: the
      // tools call all of them bad input (exit code 1 or 2).
      PyErr_SetString(input_error_type, e.what());
    }
  });
}

}  // namespace

void RegisterExceptions(py::module_& m) {
  // Never freed: the exception types live as long as the interpreter, and a static object's
  // destructor would run after the interpreter is gone.
  auto* numerical = new py::exception<NumericalError>(m, "NumericalError", PyExc_RuntimeError);
  numerical->attr("__doc__") =
      "A fit or a simulation did not converge, or the slider would tip (the tools' exit code 3).";
  auto* option =
      new py::exception<boost::program_options::error>(m, "OptionError", PyExc_ValueError);
  option->attr("__doc__") =
      "A bad option value (the tools' usage error, exit code 2); a ValueError.";
  auto* input = new py::exception<std::invalid_argument>(m, "InputError", PyExc_ValueError);
  input->attr("__doc__") =
      "Bad input: a malformed or physically invalid log, scene or file, named with the place in "
      "it (the tools' exit code 1); a ValueError. A missing file is its subclass "
      "slideid.MissingFileError, a FileNotFoundError too.";
  numerical_error_type = numerical->ptr();
  input_error_type = input->ptr();
  option_error_type = option->ptr();
  TranslateExceptions();
}

}  // namespace slideid::python

PYBIND11_MODULE(_core, m) {
  namespace sp = slideid::python;
  m.doc() = "slideid's compiled core; use the slideid package.";
  m.attr("__version__") = SLIDEID_VERSION;
  slideid::SetCeresLogging();  // as the tools: the results say how each fit ended
  sp::RegisterExceptions(m);
  sp::BindLog(m);
  sp::BindIdentify(m);
  sp::BindSimulate(m);
  sp::BindImport(m);
  sp::BindPredict(m);
  sp::BindOnline(m);
  sp::BindAdvise(m);
}
