#pragma once
// Test helper: points CYCLONEDDS_URI at the loopback-only configuration (no multicast, 127.0.0.1
// as the only peer) before any participant is created, and gives each test its own domain.

#include <cstdlib>
#include <fstream>
#include <string>
#include <unistd.h>

#include "viewline/nodes/dds.h"

namespace viewline::nodes::test {

/// Writes the loopback XML to a file of this process and sets CYCLONEDDS_URI to it.
inline std::string useLoopback() {
  const std::string path = "/tmp/viewline_nodes_loopback_" + std::to_string(getpid()) + ".xml";
  std::ofstream(path) << dds::loopbackConfig();
  setenv("CYCLONEDDS_URI", ("file://" + path).c_str(), 1);
  return path;
}

/// A domain id of this process (0..229 is valid for Cyclone's port mapping), so parallel tests do not meet.
inline int testDomain(int k = 0) { return 1 + static_cast<int>((getpid() * 7 + k) % 200); }

}  // namespace viewline::nodes::test
