#pragma once
// Ball-catching scenario ([L] §VI.C) as library code: a config struct + a seed -> per-throw
// results and a summary, so that apps/ball_catching, bench/catch_table and the tuning tool run
// exactly the same loop. The parts, each in its own file under ball_catching/:
//   config.h        the YAML reader (one per struct, validated once) and the config structs
//   world.h         the throw, the rendered world, the cameras as a runtime::FrameSource
//   registration.h  camera-to-robot registration before the throws
//   loop.h          one throw and a session on runtime::Scheduler, telemetry, live-view hooks
//   metrics.h       outcome of a throw (caught, oracle, miss reason), session summary, JSON
//   footage.h       one session on the cameras' footage (cameras[].source), no truth

#include "viewline/scenarios/ball_catching/config.h"
#include "viewline/scenarios/ball_catching/flight_fit.h"
#include "viewline/scenarios/ball_catching/footage.h"
#include "viewline/scenarios/ball_catching/loop.h"
#include "viewline/scenarios/ball_catching/metrics.h"
#include "viewline/scenarios/ball_catching/registration.h"
#include "viewline/scenarios/ball_catching/world.h"
