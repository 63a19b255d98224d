// cvo_settings_table: the settings table (every parameter of the nodelet and the tools) as
// README's markdown. With a file, rewrites its text between the "<!-- settings table -->" and
// "<!-- end settings table -->" lines instead of printing.
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "cvo_odometry/ros/node_settings.hpp"

namespace {

const char* kUsage =
    "usage: cvo_settings_table [FILE]\n"
    "  prints every parameter (name, type, default, range, meaning) as a markdown table; with\n"
    "  FILE, rewrites the table between its \"<!-- settings table -->\" and\n"
    "  \"<!-- end settings table -->\" lines instead (README.md)\n";

}  // namespace

int main(int argc, char** argv) {
  const std::string table = cvo::settingsMarkdown(cvo::NodeSettings());
  if (argc > 2 || (argc == 2 && std::string(argv[1]).rfind("-", 0) == 0)) {
    const bool help =
        argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h");
    (help ? std::cout : std::cerr) << kUsage;
    return help ? 0 : 2;
  }
  if (argc < 2) {
    std::cout << table;
    return 0;
  }
  std::ifstream in(argv[1]);
  std::stringstream text;
  text << in.rdbuf();
  const std::string begin = "<!-- settings table -->\n", end = "<!-- end settings table -->";
  std::string s = text.str();
  const auto a = s.find(begin), b = s.find(end);
  if (!in || a == std::string::npos || b == std::string::npos || b < a) {
    std::cerr << "cvo_settings_table: no settings table markers in " << argv[1] << "\n";
    return 2;
  }
  s.replace(a + begin.size(), b - a - begin.size(), table);
  std::ofstream(argv[1]) << s;
  return 0;
}
