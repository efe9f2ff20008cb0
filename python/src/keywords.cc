#include <algorithm>

#include "core.h"

namespace slideid::python {
namespace po = boost::program_options;

namespace {

/// The command-line arguments that give option `option` the Python value `value`.
void AppendArguments(const std::string& function, const std::string& keyword,
                     const po::option_description& option, py::handle value,
                     std::vector<std::string>* args) {
  const std::string name = "--" + option.long_name();
  const bool is_switch = option.semantic()->max_tokens() == 0;
  if (value.is_none()) return;
  if (py::isinstance<py::bool_>(value)) {
    const bool on = value.cast<bool>();
    // An option whose value may be left out (--fit-delay [MODE]) is a switch for bools too.
    if (is_switch || option.semantic()->min_tokens() == 0) {
      if (on) args->push_back(name);
    } else {
      args->push_back(name + "=" + (on ? "yes" : "no"));
    }
    return;
  }
  if (is_switch) {
    throw py::type_error(function + "(): " + keyword + " is a switch: pass True or False");
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    for (py::handle item : value) AppendArguments(function, keyword, option, item, args);
    return;
  }
  args->push_back(name + "=" + py::str(value).cast<std::string>());
}

}  // namespace

po::variables_map ParseKeywords(const std::string& function,
                                const po::options_description& description,
                                const py::dict& keywords, const std::vector<std::string>& reserved,
                                const std::vector<std::string>& leading) {
  std::vector<std::string> args = leading;
  for (const auto& [key, value] : keywords) {
    const std::string keyword = py::str(key).cast<std::string>();
    std::string option_name = keyword;
    std::replace(option_name.begin(), option_name.end(), '_', '-');
    const po::option_description* option = description.find_nothrow(option_name, false);
    if (option == nullptr ||
        std::find(reserved.begin(), reserved.end(), keyword) != reserved.end()) {
      throw py::type_error(function + "() got an unexpected keyword argument '" + keyword + "'");
    }
    AppendArguments(function, keyword, *option, value, &args);
  }
  po::command_line_parser parser(args);
  parser.options(description)
      .style(po::command_line_style::default_style & ~po::command_line_style::allow_guessing);
  po::variables_map vm;
  po::store(parser.run(), vm);
  po::notify(vm);
  return vm;
}

}  // namespace slideid::python
