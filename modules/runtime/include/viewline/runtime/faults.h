#pragma once
// Injected camera faults: a FrameSource decorator that makes any source (the renderer, a video, a
// recording) misbehave the way real cameras and drivers do, over windows of capture time, and
// counts what it did, so that a scenario run can show what its tracker and controller make of it.
//
//   faults:                                   # a scenario config's list (readFaultConfig)
//     - {kind: freeze, camera: 0, from_s: 2.0, to_s: 2.2}          # same image, new stamps
//     - {kind: stamp_repeat, camera: 1, from_s: 3.0, to_s: 3.1}     # the previous frame's stamp again
//     - {kind: stamp_backwards, from_s: 4.0, to_s: 4.05, step_s: 0.01}  # stamp before the previous one
//     - {kind: blackout, camera: 0, from_s: 5.0, to_s: 6.0}         # no frames: the camera stops, comes back
//     - {kind: corrupt, camera: 1, from_s: 7.0, to_s: 7.1}          # garbage pixels (uniform noise)
//
// A fault applies to the frames whose capture time lies in [from_s, to_s) of the given camera
// (every camera when `camera` is absent). A frozen frame repeats the last good image of its
// camera (a driver handing out a stale buffer); the stamps are the source's own unless a stamp
// fault is active too. Blacked-out frames are lost (grab() returns nothing, as a source does for
// a dropped frame). Corrupt images are seeded uniform noise, so runs stay reproducible.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "viewline/core/random.h"
#include "viewline/io/config.h"
#include "viewline/io/config_reference.h"
#include "viewline/runtime/frame_source.h"

namespace viewline::runtime {

/// What an injected fault does to a frame.
enum class FaultKind {
  Freeze,          ///< the camera's last good image again, with a new stamp
  StampRepeat,     ///< the stamp of the camera's previous frame again
  StampBackwards,  ///< a stamp step_s before the camera's previous frame's
  Blackout,        ///< the frame is lost (the camera stops, and comes back after the window)
  Corrupt,         ///< the image replaced by uniform noise
};
/// Number of fault kinds (the size of FaultCounters::frames).
inline constexpr std::size_t kFaultKinds = 5;

/// "freeze", "stamp_repeat", "stamp_backwards", "blackout", "corrupt".
const char* toString(FaultKind kind);

/// One injected fault: what, on which camera, over which window of capture time.
struct FaultSpec {
  FaultKind kind = FaultKind::Freeze;  ///< what it does
  std::optional<std::size_t> camera;   ///< the camera it hits (none: every camera)
  core::Timestamp from_s = 0.0;        ///< start of the window (capture time), s
  core::Timestamp to_s = 0.0;          ///< end of the window (excluded), s
  double step_s = 0.01;                ///< StampBackwards: how far before the previous stamp, s
};

/// What the decorator did, per fault kind (indexed by FaultKind).
struct FaultCounters {
  std::array<std::uint64_t, kFaultKinds> frames{};  ///< frames each kind changed (or dropped)
  /// Frames changed or dropped by kind k.
  std::uint64_t of(FaultKind k) const { return frames[static_cast<std::size_t>(k)]; }
  /// Frames any fault touched (a frame hit by two faults counts once).
  std::uint64_t touched = 0;
};

/// A FrameSource that passes another one's frames through the faults (header comment).
class FaultInjectingSource : public FrameSource {
public:
  /// Wraps `inner` (not owned; it must outlive this object). Throws core::InvalidInput on a
  /// window with to_s <= from_s, a negative or non-finite time, a step_s <= 0 or a camera index
  /// the source does not have.
  FaultInjectingSource(FrameSource& inner, std::vector<FaultSpec> faults, std::uint64_t seed);
  /// The inner source's camera count.
  std::size_t cameraCount() const override { return inner_.cameraCount(); }
  /// The inner source's next ready time (faults do not move frames in time).
  std::optional<core::Timestamp> nextReadyTime() const override { return inner_.nextReadyTime(); }
  /// The inner source's next frame, with the faults active at its capture time applied.
  std::optional<Frame> grab() override;
  /// What the faults did so far.
  const FaultCounters& counters() const { return counters_; }
  /// The faults, as given.
  const std::vector<FaultSpec>& faults() const { return faults_; }

private:
  struct CameraMemory {
    cv::Mat last_good;                       // the last image no fault touched
    std::optional<core::Timestamp> last_stamp;  // the stamp of the last frame handed out
  };
  FrameSource& inner_;
  std::vector<FaultSpec> faults_;
  core::Rng rng_;
  std::vector<CameraMemory> memory_;
  FaultCounters counters_;
  bool freezes_ = false;  // some fault freezes: keep each camera's last good image
};

/// Reads the `faults:` list of a scenario config (absent: none); throws core::InvalidInput
/// naming file:line and key on a bad kind, window or value. Camera indices are checked against
/// the source when the decorator is built.
std::vector<FaultSpec> readFaultConfig(const io::ConfigNode& root);

/// The key table of the `faults:` list (for a scenario's config_keys.cpp).
std::vector<io::ConfigKeyDoc> faultConfigKeys();

}  // namespace viewline::runtime
