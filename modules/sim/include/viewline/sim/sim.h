#pragma once
// Module sim: simulated worlds that render real images. One include for all of it:
//   physics.h   drag flight (RK4), tilting table with rolling ball, screen paths, ground target
//   scene.h     primitives, materials, textures (tag36h11, procedural), clutter, ObjectTruth
//   renderer.h  World interface, ray-cast Renderer (distortion, anti-aliasing, motion blur)
//   effects.h   sensor noise, illumination/white balance, occlusion, frame faults
//   rig.h       free-running multi-camera rig producing time-stamped frames with ground truth
//   worlds.h    ready-made worlds of the four scenarios

#include "viewline/sim/effects.h"
#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/rig.h"
#include "viewline/sim/scene.h"
#include "viewline/sim/worlds.h"
