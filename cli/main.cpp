// surftrack: the command-line tool. Dispatches to a subcommand; any error ends the process with
// one line "surftrack: error: <message>" on stderr and status 1 (2 for a malformed command
// line), never with a crash or a partial output file.
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <OpenMesh/Core/System/omstream.hh>

#include "Commands.h"
#include "Interrupt.h"
#include "Options.h"

int main(int argc, char** argv) {
  using namespace surftrack::cli;
  removeTemporariesOnTermination();  // Ctrl-C leaves no temporary file (Interrupt.h)
  // OpenMesh reports its own IO failures on stderr, over several lines; ours say it in one.
  omerr().disable();
  omlog().disable();
  omout().disable();
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty()) {
      std::cerr << mainUsage();
      return 2;
    }
    if (args[0] == "-h" || args[0] == "--help" || args[0] == "help") {
      std::cout << mainUsage();
      return 0;
    }
    if (args[0] == "--version") {
      std::cout << "surftrack " << SURFTRACK_VERSION << "\n";
      return 0;
    }
    const std::string command = args[0];
    args.erase(args.begin());
    if (command == "mesh") return runMesh(args);
    if (command == "info") return runInfo(args);
    if (command == "demo") return runDemo(args);
    if (command == "labels") return runLabels(args);
    throw UsageError("unknown command '" + command + "' (expected mesh, labels, info or demo; see surftrack --help)");
  } catch (const HelpRequested& help) {
    std::cout << help.text;
    return 0;
  } catch (const UsageError& e) {
    std::cerr << "surftrack: error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "surftrack: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::string message = e.what();
    for (char& ch : message)
      if (ch == '\n' || ch == '\r') ch = ' ';
    std::cerr << "surftrack: error: " << message << "\n";
    return 1;
  }
}
