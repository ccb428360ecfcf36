#pragma once
// viewline's own recordings: every frame of every camera, lossless, with its clock, the camera
// calibration, the config as run and (from a simulator) the truth, so that a replay feeds the
// loop exactly the frames it saw and can still be scored.
//
// Layout of a recording folder DIR:
//   recording.csv        the index, one row per grab in grab order:
//                        ready_time,camera,sequence,capture_time,stamp,file
//                        (times in s, written with 17 significant digits so they read back bit for
//                        bit; file is relative to DIR; a grab that lost its frame has an empty file,
//                        and empty camera..stamp fields unless the source knew them)
//   cam<k>/<sequence>.png  the images, PNG (lossless for 8-bit grey and BGR)
//   camera<k>.xml        camera k's calibration, ViSP XML (vpXmlParserCamera), camera name "camera<k>"
//   config.yaml          the scenario config as run (after --set edits)
//   truth.csv            optional: camera,sequence,<the scenario's truth columns>
//   <table>.csv          optional per-frame tables a scenario adds beside its frames (same layout
//                        as truth.csv), e.g. pan-tilt's ptu.csv: the unit's joint readings that
//                        back-projected each frame's detection, which a replay without the
//                        unit needs
// Text files are written atomically (io::writeTextFileAtomic), images through a temporary file
// renamed into place; the index is written by finish(), so an interrupted recording that never
// reached finish() has no recording.csv and is not mistaken for a complete one.
//
// RecordingSource reads it back as a FrameSource: the same frames with the same stamps, sequence
// numbers, lost grabs and ready times, so a deterministic loop given the replay reproduces its
// live run. The index and truth parsers refuse bad files with "<file>:<line>: ..." messages.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/runtime/frame_source.h"

namespace viewline::runtime {

/// One row of a recording's index.
struct RecordingEntry {
  double ready_time = 0.0;     ///< when the grab was made (the source's nextReadyTime), s
  std::size_t camera = 0;      ///< camera index
  std::uint64_t sequence = 0;  ///< the frame's per-camera counter
  double capture_time = 0.0;   ///< mid-exposure, s (NaN: a lost grab whose source did not know it)
  double stamp = 0.0;          ///< the driver's stamp, s (NaN: as capture_time)
  std::string file;            ///< image file relative to the folder; empty: the grab lost its frame
};

/// Parses a recording index (recording.csv text); `file` names it in messages. Refuses a wrong
/// header, a malformed or non-finite field, ready times that decrease, a sequence that does not
/// increase per camera, and image paths that are absolute or leave the folder ("..").
std::vector<RecordingEntry> parseRecordingIndex(const std::string& text, const std::string& file);

/// Per-frame truth of a recording: column names and rows keyed by (camera, sequence).
struct RecordingTruth {
  std::vector<std::string> columns;  ///< the scenario's truth columns (after camera,sequence)
  std::map<std::pair<std::size_t, std::uint64_t>, std::vector<double>> rows;  ///< (camera, sequence) -> values
};
/// Parses truth.csv text (header `camera,sequence,` then the truth columns; numeric rows; no duplicate frame).
RecordingTruth parseRecordingTruth(const std::string& text, const std::string& file);

/// Writes a recording folder (see the file comment). Not thread-safe; one writer per folder.
class RecordingWriter {
public:
  /// Creates `dir` (and parents). Throws core::InvalidInput when it already holds a recording
  /// (recording.csv): a recording is never overwritten frame by frame.
  explicit RecordingWriter(std::string dir);
  /// Writes camera<k>.xml (ViSP XML; with its distortion model when the camera has one).
  void setCamera(std::size_t camera, const core::Camera& calibration);
  /// Writes config.yaml: the scenario config as run.
  void setConfig(const std::string& yaml_text);
  /// Names the truth columns (before the first truth()); none: no truth.csv.
  void setTruthColumns(std::vector<std::string> columns);
  /// Records a frame grabbed at ready_time (the image written now, PNG).
  void frame(double ready_time, const Frame& frame);
  /// Records a grab at ready_time that lost its frame.
  void lost(double ready_time);
  /// Records a grab at ready_time that lost frame `sequence` of `camera`, whose capture time and
  /// stamp the source still knows (a driver's sequence gap); `frame.image` is not used.
  void lost(double ready_time, const Frame& frame);
  /// The truth of (camera, sequence): one value per truth column.
  void truth(std::size_t camera, std::uint64_t sequence, const std::vector<double>& values);
  /// Declares a per-frame table `<name>.csv` with `columns` (after camera,sequence); written by finish().
  void setTable(const std::string& name, std::vector<std::string> columns);
  /// A row of table `name` for (camera, sequence): one value per column of the table.
  void tableRow(const std::string& name, std::size_t camera, std::uint64_t sequence, const std::vector<double>& values);
  /// Writes recording.csv, truth.csv and the tables (atomically). Further frames are refused.
  void finish();
  /// The folder.
  const std::string& dir() const { return dir_; }
  /// Grabs recorded so far (lost ones included).
  std::size_t grabs() const { return entries_.size(); }

private:
  std::string dir_;
  std::vector<RecordingEntry> entries_;
  std::vector<std::size_t> known_lost_;  ///< entries_ indices of lost frames with known fields
  std::vector<std::string> truth_columns_;
  std::string truth_text_;
  /// Per-frame tables by name: their columns and the rows written so far (CSV text).
  std::map<std::string, std::pair<std::vector<std::string>, std::string>> tables_;
  bool finished_ = false;
};

/// A frame source that records every grab of another source into a RecordingWriter.
class RecordingFrameSource : public FrameSource {
public:
  /// Records the grabs of `inner` (both outlive this object).
  RecordingFrameSource(FrameSource& inner, RecordingWriter& writer) : inner_(inner), writer_(writer) {}
  std::size_t cameraCount() const override { return inner_.cameraCount(); }
  /// The inner source's ready time.
  std::optional<core::Timestamp> nextReadyTime() const override { return inner_.nextReadyTime(); }
  /// The inner source's grab, recorded (a lost frame too).
  std::optional<Frame> grab() override;

private:
  FrameSource& inner_;
  RecordingWriter& writer_;
};

/// A recording folder read back as a frame source (same frames, stamps, lost grabs and ready times).
class RecordingSource : public FrameSource {
public:
  /// Reads the index, the truth (when present) and checks that the first image exists; throws
  /// core::InvalidInput naming the file.
  explicit RecordingSource(std::string dir);
  std::size_t cameraCount() const override { return cameras_; }
  /// The recorded ready time of the next grab, s; nullopt after the last.
  std::optional<core::Timestamp> nextReadyTime() const override;
  /// The next recorded frame (nullopt where the live run lost it); throws InvalidInput naming an
  /// image that is missing or cannot be decoded.
  std::optional<Frame> grab() override;
  /// Whether the recording has truth (truth.csv).
  bool hasTruth() const { return !truth_.columns.empty(); }
  /// The truth columns (empty without truth).
  const std::vector<std::string>& truthColumns() const { return truth_.columns; }
  /// The truth of (camera, sequence), nullopt when the recording has none for it.
  std::optional<std::vector<double>> truth(std::size_t camera, std::uint64_t sequence) const;
  /// The per-frame table `<name>.csv` of the folder (parsed as truth.csv is), nullopt when absent;
  /// throws core::InvalidInput naming the file when it is malformed.
  std::optional<RecordingTruth> table(const std::string& name) const;
  /// The calibration of camera k from camera<k>.xml (ViSP XML), nullopt when the file is absent.
  std::optional<core::Camera> camera(std::size_t k) const;
  /// The config as run (config.yaml), "" when absent.
  std::string configText() const;
  /// The index rows.
  const std::vector<RecordingEntry>& entries() const { return entries_; }
  /// The row of the last grab (lost or not), null before the first grab.
  const RecordingEntry* lastEntry() const { return next_ > 0 ? &entries_[next_ - 1] : nullptr; }
  /// The folder.
  const std::string& dir() const { return dir_; }

private:
  std::string dir_;
  std::vector<RecordingEntry> entries_;
  RecordingTruth truth_;
  std::size_t next_ = 0;
  std::size_t cameras_ = 1;
};

// A session recording: a scenario that runs several independent units (throws, runs), each on its
// own clock, records one recording folder per unit under DIR (DIR/UNIT_iii, iii: the index, 3
// digits) and, at the top, session.json ({"scenario": NAME, "seed": S, "units": N, "unit": UNIT})
// and config.yaml (the config as run). The seed is what a replay must be given again: a scenario
// keeps simulated, from the seed, what a recording does not hold.

/// What session.json says.
struct SessionRecording {
  std::string scenario;    ///< the scenario that recorded it
  std::uint64_t seed = 0;  ///< the session's seed
  int units = 0;           ///< the number of units (throws, runs) recorded
  std::string unit;        ///< their name ("throw", "run")
};

/// The folder of unit `index` of a session recording: DIR/UNIT_iii (UNIT: "throw", "run").
std::string sessionUnitDir(const std::string& dir, const std::string& unit, int index);

/// Starts a session recording: refuses (core::InvalidInput) a folder that exists and is not empty or
/// cannot be created, then writes session.json and config.yaml (when config_text is not empty).
void beginSessionRecording(const std::string& dir, const SessionRecording& session, const std::string& config_text);

/// Reads DIR/session.json; throws core::InvalidInput naming the folder when it holds no session
/// recording of `scenario` (written by its app with --record).
SessionRecording readSessionRecording(const std::string& dir, const std::string& scenario);

/// Checks that DIR can be replayed with this seed and number of units; throws core::InvalidInput
/// saying what differs (and the --seed to give).
void checkSessionReplay(const std::string& dir, const std::string& scenario, std::uint64_t seed, int units);

}  // namespace viewline::runtime
