/// \file main.cpp
/// `nhdyn`: the library's dynamics on JSON lines, from the command line.
///
///     nhdyn <command> [options]        nhdyn --help        nhdyn <command> --help
///
/// The registry: one X(name) per subcommand, each defined in <name>.cpp as
/// `nhdyn_tool::command nhdyn_tool::command_<name>()`. Adding a subcommand is one file
/// plus one line here.
#define NHDYN_TOOL_COMMANDS(X) \
  X(model)                     \
  X(id)                        \
  X(fd)                        \
  X(linearize)                 \
  X(bound)                     \
  X(simulate)                  \
  X(view)

#include <iostream>
#include <nhdyn/version.hpp>

#include "tool.hpp"

namespace nhdyn_tool {
#define NHDYN_TOOL_DECLARE(name) command command_##name();
NHDYN_TOOL_COMMANDS(NHDYN_TOOL_DECLARE)
#undef NHDYN_TOOL_DECLARE
}  // namespace nhdyn_tool

namespace {
using nhdyn_tool::command;

std::vector<command> registry() {
#define NHDYN_TOOL_ENTRY(name) nhdyn_tool::command_##name(),
  return {NHDYN_TOOL_COMMANDS(NHDYN_TOOL_ENTRY)};
#undef NHDYN_TOOL_ENTRY
}

void print_help(std::ostream& os, const std::vector<command>& cmds) {
  os << "nhdyn: dynamics of manipulators and nonholonomic mobile manipulators on JSON lines\n\n"
        "Usage: nhdyn <command> [options] [--] [arguments]\n"
        "       nhdyn <command> --help     full help of one command\n"
        "       nhdyn --version            the version\n\n"
        "Commands:\n";
  for (const auto& c : cmds) {
    os << "  " << c.name;
    for (std::size_t i = c.name.size(); i < 12; ++i) os << ' ';
    os << c.summary << '\n';
  }
  os << "\nMODEL is a preset name (";
  const auto names = nhdyn::io::preset_names();
  for (std::size_t i = 0; i < names.size(); ++i) os << (i ? ", " : "") << names[i];
  os << "), the path of a JSON model file (docs/model-format.md), the path of a URDF\n"
        "file (*.urdf; model, id and fd; docs/trees-and-urdf.md), or the name of a model\n"
        "shipped in share/nhdyn/models.\n"
        "Line-oriented commands read one JSON object per line on stdin and write one JSON line\n"
        "per input line on stdout, in order; a bad line gets {\"error\": \"line N: ...\"} and the\n"
        "tool goes on. Numbers are printed in the shortest form that reads back exactly.\n"
        "Exit status: 0 all lines succeeded, 1 some line failed or the model is invalid,\n"
        "2 bad command line.\n\n";
  for (const auto& c : cmds) os << c.usage << '\n';
}
}  // namespace

int main(int argc, char** argv) {
  const auto cmds = registry();
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    print_help(std::cerr, cmds);
    return 2;
  }
  if (args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
    print_help(std::cout, cmds);
    return 0;
  }
  if (args[0] == "--version" || args[0] == "-V") {
    if (args.size() > 1) {
      std::cerr << "nhdyn: --version takes no arguments\n";
      return 2;
    }
    std::cout << "nhdyn " << nhdyn::version_string << '\n';
    return 0;
  }
  for (const auto& c : cmds) {
    if (args[0] != c.name) continue;
    const std::vector<std::string> rest(args.begin() + 1, args.end());
    try {
      return c.run(rest);
    } catch (const nhdyn_tool::usage_error& e) {
      std::cerr << "nhdyn " << c.name << ": " << e.what() << "\n\n" << c.usage;
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "nhdyn " << c.name << ": error: " << e.what() << '\n';
      return 1;
    }
  }
  std::cerr << "nhdyn: unknown command '" << args[0] << "' (see nhdyn --help)\n";
  return 2;
}
