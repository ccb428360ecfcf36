#include "viewline/runtime/recording.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <utility>

#include "viewline/core/error.h"
#include "viewline/io/camera_io.h"
#include "viewline/io/files.h"
#include "viewline/runtime/stamps.h"

namespace viewline::runtime {

namespace fs = std::filesystem;

namespace {

constexpr const char* kIndexHeader = "ready_time,camera,sequence,capture_time,stamp,file";
constexpr std::size_t kMaxCameras = 64;

/// 17 significant digits: every double reads back as the same double.
std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

[[noreturn]] void fail(const std::string& file, std::size_t line, const std::string& what) {
  throw core::InvalidInput(file + ":" + std::to_string(line) + ": " + what);
}

bool contentLine(const std::string& line) {
  return line.find_first_not_of(" \t\r") != std::string::npos;
}

/// Writes bytes to `path` through a temporary file renamed into place.
void writeBinaryAtomic(const std::string& path, const std::vector<unsigned char>& bytes) {
  const std::string tmp = io::temporaryPathFor(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw core::InvalidInput(path + ": cannot be written (" + std::strerror(errno) + ")");
  try {
    io::writeAllOrThrow(fd, reinterpret_cast<const char*>(bytes.data()), bytes.size(), path);
  } catch (...) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  if (::close(fd) != 0 || std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw core::InvalidInput(path + ": cannot be written (" + why + ")");
  }
}

std::string cameraName(std::size_t k) { return "camera" + std::to_string(k); }

// The index row of frame f, grabbed at ready_time (its file set by the caller).
RecordingEntry entryOf(double ready_time, const Frame& f) {
  RecordingEntry e;
  e.ready_time = ready_time;
  e.camera = f.camera;
  e.sequence = f.sequence;
  e.capture_time = f.capture_time;
  e.stamp = f.stamp;
  return e;
}
}  // namespace

// ---------------------------------------------------------------------------- parsers

std::vector<RecordingEntry> parseRecordingIndex(const std::string& text, const std::string& file) {
  std::vector<RecordingEntry> out;
  std::istringstream in(text);
  std::string line;
  std::size_t n = 0;
  bool header = false;
  std::map<std::size_t, std::uint64_t> last_sequence;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!contentLine(line)) continue;
    if (!header) {
      if (line != kIndexHeader) fail(file, n, std::string("expected the header '") + kIndexHeader + "'");
      header = true;
      continue;
    }
    const std::vector<std::string> f = csv::splitLine(line);
    if (f.size() != 6) fail(file, n, "expected 6 columns, got " + std::to_string(f.size()));
    RecordingEntry e;
    e.ready_time = csv::parseDouble(f[0], "ready_time", file, n);
    if (!out.empty() && e.ready_time < out.back().ready_time)
      fail(file, n, "ready_time " + f[0] + " is before the previous row's (grabs are in time order)");
    e.file = f[5];
    if (e.file.empty() && f[1].empty() && f[2].empty() && f[3].empty() && f[4].empty()) {
      e.capture_time = e.stamp = std::nan("");  // a lost grab the source knew nothing about
      out.push_back(e);
      continue;
    }
    const std::int64_t cam = csv::parseInt(f[1], "camera", file, n);
    if (cam < 0 || cam >= static_cast<std::int64_t>(kMaxCameras))
      fail(file, n, "camera must be in [0, " + std::to_string(kMaxCameras) + "), got " + f[1]);
    e.camera = static_cast<std::size_t>(cam);
    const std::int64_t seq = csv::parseInt(f[2], "sequence", file, n);
    if (seq < 0) fail(file, n, "sequence must be >= 0, got " + f[2]);
    e.sequence = static_cast<std::uint64_t>(seq);
    const auto prev = last_sequence.find(e.camera);
    if (prev != last_sequence.end() && e.sequence <= prev->second)
      fail(file, n, "sequence " + f[2] + " of camera " + f[1] + " does not increase");
    last_sequence[e.camera] = e.sequence;
    e.capture_time = csv::parseDouble(f[3], "capture_time", file, n);
    e.stamp = csv::parseDouble(f[4], "stamp", file, n);
    if (!e.file.empty() && (e.file.front() == '/' || e.file.find("..") != std::string::npos))
      fail(file, n, "file '" + e.file + "' must be a path inside the recording folder");
    out.push_back(e);
  }
  if (!header) throw core::InvalidInput(file + ": empty (expected the header '" + std::string(kIndexHeader) + "')");
  return out;
}

RecordingTruth parseRecordingTruth(const std::string& text, const std::string& file) {
  RecordingTruth t;
  std::istringstream in(text);
  std::string line;
  std::size_t n = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!contentLine(line)) continue;
    const std::vector<std::string> f = csv::splitLine(line);
    if (!header) {
      if (f.size() < 3 || f[0] != "camera" || f[1] != "sequence")
        fail(file, n, "expected the header 'camera,sequence,<truth columns>'");
      const std::set<std::string> unique(f.begin() + 2, f.end());
      if (unique.size() != f.size() - 2 || unique.count(""))
        fail(file, n, "truth column names must be non-empty and distinct");
      t.columns.assign(f.begin() + 2, f.end());
      header = true;
      continue;
    }
    if (f.size() != t.columns.size() + 2)
      fail(file, n, "expected " + std::to_string(t.columns.size() + 2) + " columns, got " + std::to_string(f.size()));
    const std::int64_t cam = csv::parseInt(f[0], "camera", file, n);
    const std::int64_t seq = csv::parseInt(f[1], "sequence", file, n);
    if (cam < 0 || cam >= static_cast<std::int64_t>(kMaxCameras) || seq < 0)
      fail(file, n, "camera must be in [0, " + std::to_string(kMaxCameras) + ") and sequence >= 0");
    std::vector<double> values;
    for (std::size_t i = 2; i < f.size(); ++i) values.push_back(csv::parseDouble(f[i], t.columns[i - 2], file, n));
    const auto key = std::make_pair(static_cast<std::size_t>(cam), static_cast<std::uint64_t>(seq));
    if (!t.rows.emplace(key, std::move(values)).second)
      fail(file, n, "a second truth row for camera " + f[0] + " sequence " + f[1]);
  }
  if (!header) throw core::InvalidInput(file + ": empty (expected the header 'camera,sequence,<truth columns>')");
  return t;
}

// ---------------------------------------------------------------------------- writer

RecordingWriter::RecordingWriter(std::string dir) : dir_(std::move(dir)) {
  if (dir_.empty()) throw core::InvalidInput("recording: the folder name is empty");
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_))
    throw core::InvalidInput("recording folder " + dir_ + ": cannot be created (" + ec.message() + ")");
  if (fs::exists(fs::path(dir_) / "recording.csv"))
    throw core::InvalidInput("recording folder " + dir_ + " already holds a recording (recording.csv); choose a new folder");
}

void RecordingWriter::setCamera(std::size_t camera, const core::Camera& cam) {
  const vpCameraParameters& k = cam.intrinsics;
  const bool distorted = k.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion;
  const vpCameraParameters plain(k.get_px(), k.get_py(), k.get_u0(), k.get_v0());
  io::saveVispCameraXml((fs::path(dir_) / (cameraName(camera) + ".xml")).string(), cameraName(camera), plain,
                        distorted ? std::optional<vpCameraParameters>(k) : std::nullopt, cam.width, cam.height);
}

void RecordingWriter::setConfig(const std::string& yaml_text) {
  io::writeTextFileAtomic((fs::path(dir_) / "config.yaml").string(), yaml_text);
}

void RecordingWriter::setTruthColumns(std::vector<std::string> columns) {
  if (!truth_text_.empty()) throw core::InvalidInput("recording " + dir_ + ": truth columns set after the first truth row");
  truth_columns_ = std::move(columns);
}

void RecordingWriter::frame(double ready_time, const Frame& f) {
  if (finished_) throw core::InvalidInput("recording " + dir_ + ": a frame after finish()");
  if (f.image.empty()) throw core::InvalidInput("recording " + dir_ + ": an empty image");
  char name[64];
  std::snprintf(name, sizeof name, "cam%zu/%06llu.png", f.camera, static_cast<unsigned long long>(f.sequence));
  const fs::path path = fs::path(dir_) / name;
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  std::vector<unsigned char> png;
  // Compression 1: fast; PNG is lossless at every level.
  if (!cv::imencode(".png", f.image, png, {cv::IMWRITE_PNG_COMPRESSION, 1}))
    throw core::InvalidInput(path.string() + ": the image cannot be encoded as PNG");
  writeBinaryAtomic(path.string(), png);
  RecordingEntry e = entryOf(ready_time, f);
  e.file = name;
  entries_.push_back(std::move(e));
}

void RecordingWriter::lost(double ready_time) {
  if (finished_) throw core::InvalidInput("recording " + dir_ + ": a grab after finish()");
  RecordingEntry e;
  e.ready_time = ready_time;
  entries_.push_back(e);
}

void RecordingWriter::lost(double ready_time, const Frame& f) {
  if (finished_) throw core::InvalidInput("recording " + dir_ + ": a grab after finish()");
  RecordingEntry e = entryOf(ready_time, f);  // no file: lost
  known_lost_.push_back(entries_.size());
  entries_.push_back(e);
}

void RecordingWriter::truth(std::size_t camera, std::uint64_t sequence, const std::vector<double>& values) {
  if (values.size() != truth_columns_.size())
    throw core::InvalidInput("recording " + dir_ + ": " + std::to_string(values.size()) + " truth values for " +
                             std::to_string(truth_columns_.size()) + " truth columns");
  truth_text_ += std::to_string(camera) + "," + std::to_string(sequence);
  for (double v : values) truth_text_ += "," + exact(v);
  truth_text_ += "\n";
}

void RecordingWriter::setTable(const std::string& name, std::vector<std::string> columns) {
  if (name.empty() || name == "recording" || name == "truth" || name.find_first_of("/\\.") != std::string::npos)
    throw core::InvalidInput("recording " + dir_ + ": table name '" + name +
                             "' (expected a plain file stem other than recording and truth)");
  if (columns.empty()) throw core::InvalidInput("recording " + dir_ + ": table " + name + " has no columns");
  if (tables_.count(name) != 0) throw core::InvalidInput("recording " + dir_ + ": table " + name + " declared twice");
  tables_[name] = {std::move(columns), std::string()};
}

void RecordingWriter::tableRow(const std::string& name, std::size_t camera, std::uint64_t sequence,
                               const std::vector<double>& values) {
  if (finished_) throw core::InvalidInput("recording " + dir_ + ": a table row after finish()");
  const auto it = tables_.find(name);
  if (it == tables_.end()) throw core::InvalidInput("recording " + dir_ + ": table " + name + " was not declared");
  if (values.size() != it->second.first.size())
    throw core::InvalidInput("recording " + dir_ + ": " + std::to_string(values.size()) + " values for the " +
                             std::to_string(it->second.first.size()) + " columns of table " + name);
  std::string& text = it->second.second;
  text += std::to_string(camera) + "," + std::to_string(sequence);
  for (double v : values) text += "," + exact(v);
  text += "\n";
}

void RecordingWriter::finish() {
  if (finished_) return;
  for (const auto& [name, table] : tables_) {
    std::string text = "camera,sequence";
    for (const auto& c : table.first) text += "," + c;
    io::writeTextFileAtomic((fs::path(dir_) / (name + ".csv")).string(), text + "\n" + table.second);
  }
  if (!truth_columns_.empty()) {
    std::string text = "camera,sequence";
    for (const auto& c : truth_columns_) text += "," + c;
    io::writeTextFileAtomic((fs::path(dir_) / "truth.csv").string(), text + "\n" + truth_text_);
  }
  std::string index = std::string(kIndexHeader) + "\n";
  std::size_t k = 0;
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const RecordingEntry& e = entries_[i];
    const bool known = k < known_lost_.size() && known_lost_[k] == i;
    if (known) ++k;
    if (e.file.empty() && !known) {
      index += exact(e.ready_time) + ",,,,,\n";
      continue;
    }
    index += exact(e.ready_time) + "," + std::to_string(e.camera) + "," + std::to_string(e.sequence) + "," +
             exact(e.capture_time) + "," + exact(e.stamp) + "," + e.file + "\n";
  }
  // Last: its presence marks a complete recording.
  io::writeTextFileAtomic((fs::path(dir_) / "recording.csv").string(), index);
  finished_ = true;
}

std::optional<Frame> RecordingFrameSource::grab() {
  const std::optional<core::Timestamp> ready = inner_.nextReadyTime();
  std::optional<Frame> f = inner_.grab();
  const double t = ready ? *ready : 0.0;
  if (f)
    writer_.frame(t, *f);
  else
    writer_.lost(t);
  return f;
}

// ---------------------------------------------------------------------------- source

RecordingSource::RecordingSource(std::string dir) : dir_(std::move(dir)) {
  const fs::path index = fs::path(dir_) / "recording.csv";
  if (!fs::is_directory(dir_)) throw core::InvalidInput("recording folder " + dir_ + " does not exist");
  if (!fs::exists(index))
    throw core::InvalidInput("recording folder " + dir_ + " has no recording.csv (not a recording, or one that did not finish)");
  entries_ = parseRecordingIndex(csv::readWholeFile(index.string(), "recording index"), index.string());
  const fs::path truth = fs::path(dir_) / "truth.csv";
  if (fs::exists(truth)) truth_ = parseRecordingTruth(csv::readWholeFile(truth.string(), "recording truth"), truth.string());
  std::size_t cams = 0;
  for (const RecordingEntry& e : entries_)
    if (!e.file.empty()) cams = std::max(cams, e.camera + 1);
  cameras_ = std::max<std::size_t>(cams, 1);
  for (const RecordingEntry& e : entries_) {
    if (e.file.empty()) continue;
    if (!fs::exists(fs::path(dir_) / e.file))
      throw core::InvalidInput("recording " + dir_ + ": the first image " + e.file + " listed in " + index.string() +
                               " does not exist");
    break;
  }
}

std::optional<core::Timestamp> RecordingSource::nextReadyTime() const {
  if (next_ >= entries_.size()) return std::nullopt;
  return entries_[next_].ready_time;
}

std::optional<Frame> RecordingSource::grab() {
  if (next_ >= entries_.size()) return std::nullopt;
  const RecordingEntry& e = entries_[next_++];
  if (e.file.empty()) return std::nullopt;
  const std::string path = (fs::path(dir_) / e.file).string();
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty())
    throw core::InvalidInput("recording " + dir_ + ": " + e.file + " is missing or cannot be decoded as an image");
  Frame f;
  f.camera = e.camera;
  f.sequence = e.sequence;
  f.capture_time = e.capture_time;
  f.stamp = e.stamp;
  f.image = std::move(image);
  return f;
}

std::optional<std::vector<double>> RecordingSource::truth(std::size_t camera, std::uint64_t sequence) const {
  const auto it = truth_.rows.find({camera, sequence});
  if (it == truth_.rows.end()) return std::nullopt;
  return it->second;
}

std::optional<RecordingTruth> RecordingSource::table(const std::string& name) const {
  const fs::path file = fs::path(dir_) / (name + ".csv");
  if (!fs::exists(file)) return std::nullopt;
  return parseRecordingTruth(csv::readWholeFile(file.string(), "recording table " + name), file.string());
}

std::optional<core::Camera> RecordingSource::camera(std::size_t k) const {
  const fs::path xml = fs::path(dir_) / (cameraName(k) + ".xml");
  if (!fs::exists(xml)) return std::nullopt;
  // The model with distortion when the file has one, else the plain one.
  io::CameraXml c;
  try {
    c = io::loadVispCameraXml(xml.string(), cameraName(k), io::Projection::WithDistortion);
  } catch (const core::InvalidInput&) {
    c = io::loadVispCameraXml(xml.string(), cameraName(k), io::Projection::WithoutDistortion);
  }
  core::Camera cam;
  cam.name = cameraName(k);
  cam.intrinsics = c.intrinsics;
  cam.width = c.width;
  cam.height = c.height;
  return cam;
}

std::string RecordingSource::configText() const {
  const fs::path p = fs::path(dir_) / "config.yaml";
  if (!fs::exists(p)) return {};
  return csv::readWholeFile(p.string(), "recording config");
}

// ---------------------------------------------------------------------------- sessions

std::string sessionUnitDir(const std::string& dir, const std::string& unit, int index) {
  char number[16];
  std::snprintf(number, sizeof number, "_%03d", index);
  return (fs::path(dir) / (unit + number)).string();
}

void beginSessionRecording(const std::string& dir, const SessionRecording& session, const std::string& config_text) {
  if (dir.empty()) throw core::InvalidInput("recording: the folder name is empty");
  std::error_code ec;
  // A session is never recorded over another one, nor mixed with other files.
  if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec)))
    throw core::InvalidInput("recording folder " + dir + " exists and is not empty; choose a new folder");
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw core::InvalidInput("recording folder " + dir + ": cannot be created (" +
                             (ec ? ec.message() : std::string("not a folder")) + ")");
  io::writeJsonFile((fs::path(dir) / "session.json").string(), {{"scenario", session.scenario},
                                                                {"seed", session.seed},
                                                                {"units", session.units},
                                                                {"unit", session.unit}});
  if (!config_text.empty()) io::writeTextFileAtomic((fs::path(dir) / "config.yaml").string(), config_text);
}

SessionRecording readSessionRecording(const std::string& dir, const std::string& scenario) {
  const std::string file = (fs::path(dir) / "session.json").string();
  if (!fs::is_regular_file(file))
    throw core::InvalidInput(dir + ": no session.json: not a " + scenario + " recording (written by " + scenario +
                             " --record)");
  const nlohmann::json j = io::readJsonFile(file);
  if (!j.is_object() || !j.contains("scenario") || !j["scenario"].is_string() || j["scenario"] != scenario)
    throw core::InvalidInput(file + ": not a " + scenario + " recording (\"scenario\": \"" + scenario + "\" expected)");
  if (!j.contains("seed") || !j["seed"].is_number_unsigned() || !j.contains("units") ||
      !j["units"].is_number_integer() || j["units"].get<int>() < 1 || !j.contains("unit") || !j["unit"].is_string())
    throw core::InvalidInput(file + ": expected \"seed\" (unsigned), \"units\" (>= 1) and \"unit\" (a name)");
  SessionRecording s;
  s.scenario = scenario;
  s.seed = j["seed"].get<std::uint64_t>();
  s.units = j["units"].get<int>();
  s.unit = j["unit"].get<std::string>();
  return s;
}

void checkSessionReplay(const std::string& dir, const std::string& scenario, std::uint64_t seed, int units) {
  const SessionRecording s = readSessionRecording(dir, scenario);
  if (s.seed != seed)
    throw core::InvalidInput(dir + " was recorded with seed " + std::to_string(s.seed) + ", not " + std::to_string(seed) +
                             " (what the recording does not hold is simulated from the seed): replay with --seed " +
                             std::to_string(s.seed));
  if (units > s.units)
    throw core::InvalidInput(dir + " holds " + std::to_string(s.units) + " " + s.unit + "s, not " + std::to_string(units));
}

}  // namespace viewline::runtime
