// ViSP camera XML (io::loadVispCameraXml, camera_io.h; vpXmlParserCamera underneath). The parser
// takes a path, so the input goes through a scratch file. Input layout: the first line is the
// camera name to look up, the rest the XML file; both projection models are asked for, with and
// without an image size.

#include <string>

#include "fuzz_util.h"
#include "viewline/io/camera_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using viewline::fuzz::rejectOk;
  namespace io = viewline::io;
  const std::string input = viewline::fuzz::asText(data, size);
  const auto nl = input.find('\n');
  const std::string name = nl == std::string::npos ? std::string("camera") : input.substr(0, nl);
  const std::string xml = nl == std::string::npos ? input : input.substr(nl + 1);
  const std::string path = viewline::fuzz::scratchFile("camera.xml", xml);
  rejectOk([&] { io::loadVispCameraXml(path, name, io::Projection::WithDistortion); });
  rejectOk([&] { io::loadVispCameraXml(path, name, io::Projection::WithoutDistortion, 640, 480); });
  return 0;
}
