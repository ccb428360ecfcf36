#include "viewline/robots/flir_ptu_protocol.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace viewline::robots {

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }

// First number in `s`: [+-]digits[.digits]. Hand-written (not strtod) so that "inf", "nan",
// hexadecimal and exponents in line noise are never read as values.
void firstNumber(std::string_view s, PtuReply& reply) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::size_t j = i;
    if ((s[j] == '-' || s[j] == '+') && j + 1 < s.size() && isDigit(s[j + 1])) ++j;
    if (!isDigit(s[j])) continue;
    while (j < s.size() && isDigit(s[j])) ++j;
    bool decimal = false;
    if (j + 1 < s.size() && s[j] == '.' && isDigit(s[j + 1])) {
      decimal = true;
      ++j;
      while (j < s.size() && isDigit(s[j])) ++j;
    }
    const std::string token(s.substr(i, j - i));
    if (token.size() > 18) return;  // beyond what a unit reports: not a value
    reply.number = std::strtod(token.c_str(), nullptr);
    if (!decimal) reply.integer = std::strtoll(token.c_str(), nullptr, 10);
    return;
  }
}

}  // namespace

std::string printableLine(std::string_view line) {
  std::string out;
  for (char c : line) {
    if (out.size() >= 60) {
      out += "...";
      break;
    }
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", static_cast<unsigned>(u));
      out += hex;
    } else {
      out += c;
    }
  }
  return out;
}

PtuErrorClass classifyPtuError(std::string_view message) {
  const std::string m = lower(message);
  const auto has = [&](const char* w) { return m.find(w) != std::string::npos; };
  if (has("position") && (has("exceeded") || has("limit"))) return PtuErrorClass::PositionLimit;
  if (has("speed") && (has("exceeded") || has("limit"))) return PtuErrorClass::SpeedLimit;
  if (has("limit") || m == "p" || m == "t") return PtuErrorClass::LimitHit;
  if (has("illegal command") || has("unknown command") || has("not allowed")) return PtuErrorClass::IllegalCommand;
  if (has("illegal") || has("argument")) return PtuErrorClass::IllegalArgument;
  return PtuErrorClass::Other;
}

const char* toString(PtuErrorClass error) {
  switch (error) {
    case PtuErrorClass::PositionLimit: return "position limit";
    case PtuErrorClass::SpeedLimit: return "speed limit";
    case PtuErrorClass::LimitHit: return "limit hit";
    case PtuErrorClass::IllegalCommand: return "illegal command";
    case PtuErrorClass::IllegalArgument: return "illegal argument";
    case PtuErrorClass::Other: return "error";
  }
  return "?";
}

PtuReply parsePtuReply(std::string_view line) {
  if (line.size() > 256) {
    throw PtuProtocolError("PTU reply too long (" + std::to_string(line.size()) + " characters): '" + printableLine(line) + "'");
  }
  for (char c : line) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 && c != '\t') || u >= 0x7f) {
      throw PtuProtocolError("PTU reply holds control or non-ASCII bytes (line noise or a wrong baud rate?): '" +
                             printableLine(line) + "'");
    }
  }
  std::size_t i = 0;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  if (i == line.size() || (line[i] != '*' && line[i] != '!')) {
    throw PtuProtocolError("PTU reply neither '*' (success) nor '!' (error): '" + printableLine(line) + "'");
  }
  PtuReply reply;
  reply.ok = line[i] == '*';
  std::string_view rest = line.substr(i + 1);
  while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
  while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t')) rest.remove_suffix(1);
  reply.text = std::string(rest);
  firstNumber(rest, reply);
  if (!reply.ok) reply.error = classifyPtuError(rest);
  return reply;
}

double arcsecToRad(double arcsec) { return arcsec / 3600.0 * M_PI / 180.0; }

}  // namespace viewline::robots
