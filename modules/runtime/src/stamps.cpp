#include "viewline/runtime/stamps.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "viewline/core/error.h"

namespace viewline::runtime {

namespace csv {

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

[[noreturn]] void fail(const std::string& file, std::size_t line, const std::string& what) {
  throw core::InvalidInput(file + ":" + std::to_string(line) + ": " + what);
}
}  // namespace

std::vector<std::string> splitLine(const std::string& line_in) {
  std::string line = line_in;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    if (comma == std::string::npos) {
      out.push_back(line.substr(start));
      return out;
    }
    out.push_back(line.substr(start, comma - start));
    start = comma + 1;
  }
}

double parseDouble(const std::string& field, const std::string& column, const std::string& file, std::size_t line) {
  const std::string f = trim(field);
  // strtod alone reads "1x" as 1 and "" as 0: the whole field must be consumed.
  char* end = nullptr;
  errno = 0;
  const double v = f.empty() ? 0.0 : std::strtod(f.c_str(), &end);
  if (f.empty() || end != f.c_str() + f.size() || errno == ERANGE || !std::isfinite(v))
    fail(file, line, column + ": expected a finite number, got '" + field + "'");
  return v;
}

std::int64_t parseInt(const std::string& field, const std::string& column, const std::string& file, std::size_t line) {
  const std::string f = trim(field);
  char* end = nullptr;
  errno = 0;
  const long long v = f.empty() ? 0 : std::strtoll(f.c_str(), &end, 10);
  if (f.empty() || end != f.c_str() + f.size() || errno == ERANGE)
    fail(file, line, column + ": expected an integer, got '" + field + "'");
  return static_cast<std::int64_t>(v);
}

std::string readWholeFile(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InvalidInput(what + " " + path + ": cannot be read (" + std::strerror(errno) + ")");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw core::InvalidInput(what + " " + path + ": read error");
  return s.str();
}

}  // namespace csv

std::vector<StampEntry> parseStamps(const std::string& text, const std::string& file) {
  std::vector<StampEntry> out;
  std::istringstream in(text);
  std::string line;
  std::size_t n = 0;
  bool first_content = true;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    const std::vector<std::string> f = csv::splitLine(line);
    if (first_content && f.size() == 2 && f[0] == "index" && f[1] == "stamp") {
      first_content = false;
      continue;
    }
    first_content = false;
    if (f.size() != 2)
      throw core::InvalidInput(file + ":" + std::to_string(n) + ": expected 2 columns 'index,stamp', got " +
                               std::to_string(f.size()));
    StampEntry e;
    e.index = csv::parseInt(f[0], "index", file, n);
    e.stamp = csv::parseDouble(f[1], "stamp", file, n);
    if (e.index < 0) throw core::InvalidInput(file + ":" + std::to_string(n) + ": index must be >= 0");
    if (!out.empty() && e.index <= out.back().index)
      throw core::InvalidInput(file + ":" + std::to_string(n) + ": index " + std::to_string(e.index) +
                               " does not increase (previous " + std::to_string(out.back().index) + ")");
    if (!out.empty() && !(e.stamp > out.back().stamp))
      throw core::InvalidInput(file + ":" + std::to_string(n) + ": stamp " + f[1] +
                               " does not increase (time stamps must be strictly increasing)");
    out.push_back(e);
  }
  if (out.empty()) throw core::InvalidInput(file + ": no 'index,stamp' line");
  return out;
}

std::vector<StampEntry> readStampsFile(const std::string& path) {
  return parseStamps(csv::readWholeFile(path, "stamps file"), path);
}

}  // namespace viewline::runtime
