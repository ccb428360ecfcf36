#pragma once
// The waypoint particle filter moved to tracking (viewline/tracking/planar_target/waypoint_particles.h).
// transitional: remove once scenarios use tracking::
#include "viewline/tracking/planar_target/waypoint_particles.h"

namespace viewline::control {
using tracking::WaypointParticleConfig;
using tracking::WaypointParticleFilter;
}  // namespace viewline::control
