#pragma once
// Hardware back ends of PanTiltUnit, thin wrappers of ViSP's drivers. Each is
// compiled only when the installed ViSP was built with its SDK:
//
//   FlirPtuUnit   vpRobotFlirPtu   VISP_HAVE_FLIR_PTU_SDK   (FLIR PTU-D46 / E46 over serial or TCP)
//   Ptu46Unit     vpRobotPtu46     VISP_HAVE_PTU46          (Directed Perception PTU-46)
//   BiclopsUnit   vpRobotBiclops   VISP_HAVE_BICLOPS        (TRACLabs Biclops)
//
// Debian 12's ViSP 3.5 package defines none of the three, so the default build
// contains none of these classes (`pan_tilt_hardware_available` lists what was
// compiled). Each unit is put in velocity control at construction; commands are
// clipped with limitVelocityCommand() by the caller as for the simulator; the
// time stamps passed in are the caller's clock (the drivers act "now").

#include <memory>
#include <string>
#include <vector>
#include <visp3/core/vpConfig.h>

#include "viewline/robots/pan_tilt_unit.h"

namespace viewline::robots {

/// Names of the hardware back ends compiled into this build (empty on Debian's ViSP).
std::vector<std::string> panTiltHardwareAvailable();

/// Which hardware pan-tilt unit to open and how (ViSP driver, device, limits, latency).
struct PanTiltHardwareConfig {
  std::string backend;          ///< "flir_ptu", "ptu46" or "biclops"
  std::string device;           ///< serial port (flir_ptu, ptu46) or Biclops config file
  int baudrate = 9600;          ///< flir_ptu only
  PanTiltLimits limits = PanTiltLimits::flirPtuD46();  ///< enforced by the caller
  double latency = 0.03;        ///< nominal command latency, s
};

/// Opens the named back end. Throws core::InvalidInput naming `backend` when it is unknown or
/// was not compiled into this build.
std::unique_ptr<PanTiltUnit> openPanTiltHardware(const PanTiltHardwareConfig& config);

}  // namespace viewline::robots
