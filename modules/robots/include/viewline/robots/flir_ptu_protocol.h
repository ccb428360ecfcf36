#pragma once
// The FLIR (Directed Perception) PTU ASCII protocol: command strings and reply parsing, shared by
// the driver (flir_ptu.h) and the emulator (ptu_emulator.h). Reference: PTU-D46 User's Manual
// v2.14.0, chapter 4 (Command Reference), and the E-series Command Reference Manual v4.00.
//
//  - A command is letters, an optional signed integer argument, and a delimiter (space, CR or
//    LF), case-insensitive: "PP" queries the pan position, "PP-500 " sets it.
//  - Every command gets one reply line: "*" (success) with the queried value in terse feedback
//    ("* 22") or a sentence in verbose feedback ("* Current Pan position is 22"); "!" and a
//    message on error ("! Maximum allowable Pan position exceeded").
//  - With echo on (the factory default) the command comes back in front of its reply
//    ("PP * 22"); the driver turns echo off first (ED) and feedback to terse (FT).
//
// Units: positions (steps) for angles, positions/s for speeds, positions/s² for accelerations;
// PR/TR give the resolution in seconds of arc per position.

#include <optional>
#include <string>
#include <string_view>

#include "viewline/core/error.h"

namespace viewline::robots {

/// A reply line that is neither "*..." nor "!..." (line noise, wrong baud rate, echo left on).
class PtuProtocolError : public core::Error {
public:
  using core::Error::Error;
};

/// What a unit's "!" error reply means.
enum class PtuErrorClass {
  PositionLimit,   ///< position beyond the axis limits ("Maximum/Minimum allowable ... position exceeded")
  SpeedLimit,      ///< speed beyond the speed bounds ("... speed exceeded")
  LimitHit,        ///< an axis ran into a limit while moving ("!P" / "!T", "limit hit")
  IllegalCommand,  ///< unknown command or one not allowed in the current mode
  IllegalArgument, ///< an argument the unit cannot parse
  Other,           ///< any other error message
};

/// One parsed reply line.
struct PtuReply {
  bool ok = false;                 ///< true for "*", false for "!"
  std::string text;                ///< the text after the '*' or '!', trimmed
  std::optional<long long> integer;  ///< the first number in the text when it is an integer
  std::optional<double> number;    ///< the first number in the text (integer or decimal)
  PtuErrorClass error = PtuErrorClass::Other;  ///< for "!" replies: what went wrong
};

/// Parses one reply line (terminator already removed). Throws PtuProtocolError naming the line
/// (printable, truncated) when it does not start with '*' or '!' after leading blanks, holds
/// control characters, or is longer than 256 characters.
PtuReply parsePtuReply(std::string_view line);

/// Classifies the message of a "!" reply (case-insensitive key words).
PtuErrorClass classifyPtuError(std::string_view message);

/// Short name of an error class ("position limit", "illegal command", ...).
const char* toString(PtuErrorClass error);

/// The line shown in messages: control characters as backslash-x and two hex digits, at most 60 characters.
std::string printableLine(std::string_view line);

/// Seconds of arc per position -> radians per position.
double arcsecToRad(double arcsec);

}  // namespace viewline::robots
