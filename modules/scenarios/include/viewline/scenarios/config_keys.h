#pragma once
// The config reference of each scenario: its reader, the shipped files that use it and the unit
// and meaning of every key, kept next to the reader (modules/scenarios/<name>/config_keys.cpp).
// apps/viewline_config_reference writes docs/config_reference.md from them; the unit test
// ScenarioConfigKeys.* fails when a reader reads a key that has no entry, or an entry is never read.

#include <vector>

#include "viewline/io/config_reference.h"

namespace viewline::scenarios {

/// The dart scenario's config (apps/dart_tracking): reader, shipped files and key table.
io::ConfigReferenceSection dartConfigReference();
/// The ball-catching scenario's config (apps/ball_catching): reader, shipped files and key table.
io::ConfigReferenceSection ballCatchingConfigReference();
/// The pan-tilt scenario's config (apps/pan_tilt_tracking): reader, shipped files and key table.
io::ConfigReferenceSection panTiltConfigReference();
/// The table-ball scenario's config (apps/table_ball_balancing): reader, shipped files and key table.
io::ConfigReferenceSection tableBallConfigReference();
/// The mobile-capture scenario's config (apps/mobile_capture): reader, shipped files and key table.
io::ConfigReferenceSection mobileCaptureConfigReference();

/// Every scenario config, in the order of the reference.
inline std::vector<io::ConfigReferenceSection> scenarioConfigReferences() {
  return {dartConfigReference(), ballCatchingConfigReference(), panTiltConfigReference(), tableBallConfigReference(),
          mobileCaptureConfigReference()};
}

}  // namespace viewline::scenarios
