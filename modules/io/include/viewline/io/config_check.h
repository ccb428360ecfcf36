#pragma once
// The last step of every scenario config reader: no key left unread, then the struct's own
// validate(), its error prefixed with the file name so the user knows which file to fix.

#include "viewline/core/error.h"
#include "viewline/io/config.h"

namespace viewline::io {

/// root.finish() (unknown keys are refused with their line), then cfg.validate(); an InvalidInput
/// from validate() is re-thrown as "<file>: <message>".
template <class Config>
void finishAndValidate(const ConfigNode& root, const Config& cfg) {
  root.finish();
  try {
    cfg.validate();
  } catch (const core::InvalidInput& e) {
    throw core::InvalidInput(root.fileName() + ": " + e.what());
  }
}

}  // namespace viewline::io
