#pragma once
// Ready-made worlds of the four scenarios (SPEC §2-§5). Each is a World (renderer.h): a static,
// textured environment plus moving objects queried by time. Named objects (ground truth):
//   BallFlightWorld  "ball"                       sphere, flights with quadratic drag ([L])
//   DartWorld        "dart" (+ static "board")    dart frame: origin at the barrel's rear, z = tip
//   TableWorld       "table", "ball", "tag<id>"   table frame: surface centre, z = surface normal
//   ScreenWorld      "screen", "target"           screen frame: centre, x right, y down, z into it
//   GroundWorld      "target"                     8x6 cm red box on the floor, x along its heading
// Worlds that wrap physics hold a copy of precomputed trajectories (DragFlight, ScreenPath,
// GroundTarget) or a reference to a TiltTable that the caller owns and steps (closed loop).

#include <vector>

#include "viewline/sim/physics.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/scene.h"

namespace viewline::sim {

/// A closed room: a textured floor (z = 0, centred at the origin, side floor_size) and four
/// textured walls standing on its edges (facing inwards, height wall_height), so every camera
/// inside sees texture in all directions. Seeded procedural textures (value noise, finest cells
/// of about floor_size / 1024).
struct RoomParams {
  double floor_size = 14.0;     ///< m
  bool walls = true;  ///< four textured walls around the floor
  double wall_height = 6.0;     ///< m
  NoiseTextureParams floor_texture{1024, 8, 8, 0.5, 0.75, Eigen::Vector3d(0.35, 0.42, 0.45)};  ///< floor texture
  NoiseTextureParams wall_texture{1024, 8, 6, 0.45, 0.75, Eigen::Vector3d(0.62, 0.6, 0.55)};  ///< wall texture
};
/// A textured closed room (floor and walls) to surround a scenario with texture (seeded).
Scene makeRoom(const RoomParams& params, core::Rng& rng);

/// Name, radius and colour of the flying ball.
struct BallAppearance {
  std::string name = "ball";  ///< name in the ground truth
  double radius = 0.025;                                        ///< m (the 5 cm ball)
  Eigen::Vector3d albedo_bgr = Eigen::Vector3d(0.08, 0.45, 0.95);  ///< orange
};

/// One or more ball flights; at time t the ball of the flight covering t is drawn (none when no
/// flight covers t). Flights must not overlap in time.
class BallFlightWorld : public World {
public:
  /// A world of ball flights (non-overlapping in time) inside a static environment.
  BallFlightWorld(std::vector<DragFlight> flights, Scene environment, BallAppearance ball = {},
                  Lighting lighting = {});
  const Scene& staticScene() const override { return environment_; }
  void dynamicObjects(double t, std::vector<Primitive>& out) const override;
  Lighting lighting() const override { return lighting_; }
  /// The flights, in time order.
  const std::vector<DragFlight>& flights() const { return flights_; }
  /// The flight covering t, or nullptr.
  const DragFlight* flightAt(double t) const;

private:
  std::vector<DragFlight> flights_;
  Scene environment_;
  BallAppearance ball_;
  Lighting lighting_;
};

/// A dart in flight (oriented along its velocity, dartPose) towards a board on a wall.
class DartWorld : public World {
public:
  /// board: pose of the board frame (z into the wall), radius 0.225 m, named "board".
  DartWorld(DragFlight flight, Scene environment, const Eigen::Isometry3d& w_M_board, Lighting lighting = {});
  const Scene& staticScene() const override { return environment_; }
  void dynamicObjects(double t, std::vector<Primitive>& out) const override;
  Lighting lighting() const override { return lighting_; }
  /// The dart's flight.
  const DragFlight& flight() const { return flight_; }

private:
  DragFlight flight_;
  Scene environment_;
  Lighting lighting_;
};

/// Colours and geometry of the tilting table (surface, borders, ball, optional tags).
struct TableAppearance {
  Eigen::Vector3d surface_bgr = Eigen::Vector3d(0.12, 0.1, 0.8);    ///< red
  Eigen::Vector3d border_bgr = Eigen::Vector3d(0.05, 0.05, 0.05);   ///< black
  double border_width = 0.02;                                       ///< m, outside the L square
  double border_height = 0.02;                                      ///< m, above the surface
  Eigen::Vector3d ball_bgr = Eigen::Vector3d(0.2, 0.7, 0.15);       ///< green
  bool tags = false;            ///< four tag36h11 tags on a white plate around the borders
  double tag_size = 0.05;       ///< m (black square)
  int first_tag_id = 0;         ///< ids first_tag_id..+3 at corners (-,-), (+,-), (+,+), (-,+)
};

/// [M]'s scene: the tilting table (red surface, raised black borders) with the green ball,
/// following a TiltTable that the caller owns and advances (state history interpolated for
/// motion blur; querying a time outside the history clamps to it).
class TableWorld : public World {
public:
  /// A world following `table` (owned and advanced by the caller, must outlive the world).
  TableWorld(const TiltTable& table, Scene environment, TableAppearance appearance = {}, Lighting lighting = {});
  const Scene& staticScene() const override { return environment_; }
  void dynamicObjects(double t, std::vector<Primitive>& out) const override;
  Lighting lighting() const override { return lighting_; }
  /// The simulator's tag frame (makeTag36h11: z into the table) of the i-th table tag (i = 0..3)
  /// in the table frame (surface centre, z = surface normal, up).
  Eigen::Isometry3d table_M_tag(int i) const;
  /// vpDetectorAprilTag's tag frame (z out of the tag, i.e. along the table normal) of the i-th
  /// table tag in the table frame: table_M_tag(i) * simTag_M_vispTag(). This is what a
  /// vision::TagOnTable layout needs.
  Eigen::Isometry3d table_M_vispTag(int i) const;
  /// The appearance in use.
  const TableAppearance& appearance() const { return look_; }

private:
  const TiltTable& table_;
  Scene environment_;
  TableAppearance look_;
  Lighting lighting_;
};

/// Size and colours of the projection screen and the projected disc.
struct ScreenAppearance {
  double width = 2.4,                                                ///< screen width, m
         height = 1.8;                                               ///< screen height, m
  Eigen::Vector3d screen_bgr = Eigen::Vector3d(0.85, 0.85, 0.85);    ///< lit by the projector (unlit)
  double disc_radius = 0.06;                                         ///< m
  Eigen::Vector3d disc_bgr = Eigen::Vector3d(0.08, 0.08, 0.08);      ///< the projected dark circle
};

/// [T]'s scene: a dark disc projected on a screen, moving along a ScreenPath (screen frame).
class ScreenWorld : public World {
public:
  /// A world of a disc moving along `path` on a screen at pose w_M_screen (screen frame x right, y down, z into it).
  ScreenWorld(ScreenPath path, const Eigen::Isometry3d& w_M_screen, Scene environment,
              ScreenAppearance appearance = {}, Lighting lighting = {});
  const Scene& staticScene() const override { return scene_; }
  void dynamicObjects(double t, std::vector<Primitive>& out) const override;
  Lighting lighting() const override { return lighting_; }
  /// The target's path (screen frame).
  const ScreenPath& path() const { return path_; }
  /// World position of the target centre at time t.
  Eigen::Vector3d target_w(double t) const;

private:
  ScreenPath path_;
  Eigen::Isometry3d w_M_screen_;
  Scene scene_;
  ScreenAppearance look_;
  Lighting lighting_;
};

/// Size and colour of the ground target box.
struct GroundObjectAppearance {
  Eigen::Vector3d extents = Eigen::Vector3d(0.08, 0.06, 0.05);      ///< m (8 x 6 cm footprint)
  Eigen::Vector3d albedo_bgr = Eigen::Vector3d(0.1, 0.1, 0.85);     ///< red
};

/// [K]'s scene: a red object driven by a GroundTarget on a textured floor.
class GroundWorld : public World {
public:
  /// A world of the ground target box driven by `target` on a floor.
  GroundWorld(GroundTarget target, Scene environment, GroundObjectAppearance appearance = {}, Lighting lighting = {});
  const Scene& staticScene() const override { return environment_; }
  void dynamicObjects(double t, std::vector<Primitive>& out) const override;
  Lighting lighting() const override { return lighting_; }
  /// The ground target's trajectory.
  const GroundTarget& target() const { return target_; }

private:
  GroundTarget target_;
  Scene environment_;
  GroundObjectAppearance look_;
  Lighting lighting_;
};

}  // namespace viewline::sim
