// Camera rig files (io::loadRig, rig.h). The input is the rig YAML; its relative intrinsics paths
// resolve against the committed calib/rigs/dart folder (side.xml, rear.xml, intrinsics/*.yaml), as
// loadRig(path) resolves them against the rig file's folder. loadRig(path) is loadFile (fuzzed by
// fuzz_scenario_yaml) + loadRig(node) + finish(), which is what runs here.
//
// Inputs naming files under /proc, /sys or /dev are skipped: a rig may name any file (the user's
// own), and reading such a file (e.g. /proc/kmsg as root) can block, which is not a parser defect.

#include <string>

#include "fuzz_util.h"
#include "viewline/io/rig.h"

#ifndef VIEWLINE_SOURCE_DIR
#error "VIEWLINE_SOURCE_DIR must name the source tree (fuzz/CMakeLists.txt)"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = viewline::io;
  const std::string text = viewline::fuzz::asText(data, size);
  for (const char* special : {"/proc", "/sys", "/dev"})
    if (text.find(special) != std::string::npos) return 0;
  viewline::fuzz::rejectOk([&] {
    const io::ConfigNode root = io::ConfigNode::fromString(text, "rig.yaml", VIEWLINE_SOURCE_DIR "/calib/rigs/dart");
    io::loadRig(root);
    root.finish();
  });
  return 0;
}
