// OpenCV calibration files (io::loadOpenCvIntrinsics, camera_io.h; cv::FileStorage underneath),
// YAML or XML (the scratch file is named .xml when the input starts with '<', else .yaml), then
// the conversion to ViSP's model the rig loader applies.

#include <string>

#include "fuzz_util.h"
#include "viewline/io/camera_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = viewline::io;
  const std::string text = viewline::fuzz::asText(data, size);
  const bool xml = !text.empty() && text[0] == '<';
  const std::string path = viewline::fuzz::scratchFile(xml ? "intrinsics.xml" : "intrinsics.yaml", text);
  viewline::fuzz::rejectOk([&] {
    const io::OpenCvIntrinsics o = io::loadOpenCvIntrinsics(path);
    io::toVispWithoutDistortion(o, path);
  });
  return 0;
}
