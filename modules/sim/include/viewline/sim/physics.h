#pragma once
// Physics of the simulated worlds, SI units throughout (m, s, rad, kg).
//
// World frame: z is up, gravity g_w = (0, 0, -9.81) m/s².
//
// * DragFlight: a body in free flight with quadratic air drag,
//       p̈ = g - k |ṗ| ṗ,   k = ρ Cd A / (2 m),  A = π r_ref²,
//   integrated with classical RK4 on a fixed sub-step (default 1 ms). With k = 0 RK4 is
//   exact for the parabola p = p0 + v0 t + ½ g t².
// * TiltTable: a solid ball rolling without slipping on a square table whose two tilt
//   angles are actuated (angle and rate limits, pure actuator delay). In the table frame
//   (x, y on the surface, z along its normal) the ball accelerates with
//       a_xy = (5/7) [t_R_w g_w]_xy      (SPEC §1.2, [M] eqs 4.13-4.30)
//   (inertial forces due to the table's own rotation are neglected, as in [M]). Borders
//   are inelastic: the centre stays in |px|, |py| <= L/2 - r, the velocity component into
//   a border is set to zero on contact.
// * ScreenPath: a 2-D target on a screen moving at constant speed along a rectangle, a
//   circle or a random polyline ([T]).
// * GroundTarget: a unicycle on the floor driven by [K]'s speed and turn-rate profiles,
//   (v, ω) constant over each profile step k (period profile_period) and integrated exactly as
//   circular arcs ([K]'s midpoint formula δx = v dt cos(θ + ω dt/2) is its 2nd-order approximation).

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <vector>

#include "viewline/core/random.h"

namespace viewline::sim {

constexpr double kGravity = 9.81;  ///< m/s²

/// World gravity vector (z up).
inline Eigen::Vector3d gravityWorld() { return {0.0, 0.0, -kGravity}; }

/// Aerodynamic parameters of a body in flight.
struct DragBody {
  double mass = 0.057;               ///< kg (tennis-ball-like mass, our choice for the 5 cm ball)
  double reference_radius = 0.025;   ///< m, radius of the reference area A = π r² (ball: its radius)
  double drag_coefficient = 0.5;     ///< Cd (a sphere at Re ~ 1e4-1e5: 0.47-0.55)
  double air_density = 1.2;          ///< kg/m³

  /// k = ρ Cd π r² / (2 m) in 1/m; throws InvalidInput for non-positive mass/radius or negative Cd/ρ.
  double dragPerMass() const;

  /// The 5 cm ball of the ball scenarios ([L]: ball 5 cm, hole 6 cm): r = 0.025 m, 0.057 kg, Cd 0.5.
  static DragBody ball5cm() { return {}; }
  /// A steel-tip dart: 22 g, drag referred to a 7 mm barrel with Cd = 1.0 (barrel + flights).
  static DragBody dart() { return {0.022, 0.0035, 1.0, 1.2}; }
  /// No air at all (closed-form parabola).
  static DragBody vacuum() { return {0.057, 0.025, 0.0, 0.0}; }
};

/// Position and velocity of a body in flight (world frame).
struct FlightState {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< position (world), m
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  ///< velocity (world), m/s
};

/// Time derivative of (p, v) under gravity g_w and drag k: (v, g - k |v| v).
FlightState flightDerivative(const FlightState& s, double k, const Eigen::Vector3d& g_w);

/// One classical RK4 step of length dt.
FlightState rk4Step(const FlightState& s, double dt, double k, const Eigen::Vector3d& g_w);

/// A precomputed flight on [t0, t0 + duration]: knots every `step` seconds, exact RK4 partial step
/// between knots, so state(t) is smooth and costs one RK4 step.
class DragFlight {
public:
  /// Throws InvalidInput (naming the field) for NaN state, duration <= 0 or step <= 0.
  DragFlight(const FlightState& initial, double t0, double duration, const DragBody& body,
             double step = 1e-3, const Eigen::Vector3d& g_w = gravityWorld());

  /// State at time t in [t0, t0 + duration]; throws InvalidInput outside.
  FlightState state(double t) const;
  /// Start of the precomputed flight, s.
  double startTime() const { return t0_; }
  /// End of the precomputed flight, s.
  double endTime() const { return t0_ + duration_; }
  /// Drag constant k = ρ Cd A / (2 m), 1/m.
  double dragPerMass() const { return k_; }
  /// Aerodynamic parameters of the body.
  const DragBody& body() const { return body_; }

private:
  double t0_, duration_, step_, k_;
  DragBody body_;
  Eigen::Vector3d g_w_;
  std::vector<FlightState> knots_;
};

/// Closed-form drag-free position p0 + v0 t + ½ g t².
Eigen::Vector3d parabola(const FlightState& initial, double t, const Eigen::Vector3d& g_w = gravityWorld());

/// Pose w_M_dart of a dart flying along `velocity`: its body axis (object z, tip at +z) aligned
/// with the velocity (a stable dart weather-vanes into the relative wind); roll fixed so that the
/// object x axis stays horizontal.
Eigen::Isometry3d dartPose(const Eigen::Vector3d& position_w, const Eigen::Vector3d& velocity_w);

// ----------------------------------------------------------------------------------------------
// Ball rolling on an actuated tilting table.

/// Geometry, limits, delay and integration settings of the simulated tilting table.
struct TiltTableParams {
  double side = 0.3;                   ///< L, m (red surface, SPEC §3)
  double ball_radius = 0.025;          ///< r, m
  double max_angle = 0.35;             ///< |tilt| limit per axis, rad (~20°)
  double max_rate = 1.5;               ///< |tilt rate| limit per axis, rad/s
  double delay = 0.02;                 ///< pure actuator delay between command and motion, s
  double substep = 1e-3;               ///< integration sub-step, s
  double history = 1.0;                ///< seconds of state history kept for interpolation (motion blur)
  /// Pose of the table's untilted frame (origin at the surface centre, z up along the normal).
  Eigen::Isometry3d w_M_base = Eigen::Isometry3d::Identity();
};

/// State of the table-ball system at one instant.
struct TiltTableState {
  double t = 0.0;  ///< time of the state, s
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();  ///< (about base x, then about tilted y), rad
  Eigen::Vector2d p = Eigen::Vector2d::Zero();     ///< ball centre on the table (table frame), m
  Eigen::Vector2d v = Eigen::Vector2d::Zero();     ///< ball velocity on the table, m/s
};

/// Rolling ball on a table tilted by the commanded angles. Frames: w_M_table = w_M_base ·
/// Rx(tilt.x) · Ry(tilt.y); the ball centre is at (px, py, r) in the table frame.
class TiltTable {
public:
  /// Table with these parameters, starting from `initial` (time, tilt, ball position and velocity).
  explicit TiltTable(const TiltTableParams& params, const TiltTableState& initial = {});

  /// Command tilt angles (rad) at time t (>= the last command's time); applied after the delay,
  /// followed at the rate limit and clamped to the angle limit.
  void command(double t, const Eigen::Vector2d& tilt);
  /// An instantaneous push: adds dv (table frame, m/s) to the ball velocity.
  void push(const Eigen::Vector2d& dv);
  /// Advance the simulation to time t (>= current time) with sub-steps.
  void advanceTo(double t);

  /// Current state (at the simulated time).
  const TiltTableState& state() const { return state_; }
  /// The parameters in use.
  const TiltTableParams& params() const { return params_; }
  /// State at an earlier time (linear interpolation of the recorded history, clamped to it).
  TiltTableState stateAt(double t) const;

  /// Table frame in world for given tilt angles.
  Eigen::Isometry3d tablePose(const Eigen::Vector2d& tilt) const;
  /// In-plane acceleration (5/7)[t_R_w g]_xy for given tilt angles.
  Eigen::Vector2d rollingAcceleration(const Eigen::Vector2d& tilt) const;
  /// Largest |px|, |py| of the ball centre: L/2 - r.
  double limit() const { return 0.5 * params_.side - params_.ball_radius; }

private:
  void step(double dt);
  TiltTableParams params_;
  TiltTableState state_;
  std::deque<std::pair<double, Eigen::Vector2d>> commands_;
  Eigen::Vector2d target_ = Eigen::Vector2d::Zero();
  double last_command_time_ = -1e300;
  std::deque<TiltTableState> history_;
};

// ----------------------------------------------------------------------------------------------
// Screen target ([T]).

/// Shape of the screen target's path: rectangle, circle or random polyline ([T]).
enum class PathShape { Rectangle, Circle, Random };

/// Path of the screen target: shape, speed and size (screen frame, m).
struct ScreenPathParams {
  PathShape shape = PathShape::Rectangle;  ///< path shape
  double speed = 0.2;                                    ///< constant speed, m/s
  Eigen::Vector2d center = Eigen::Vector2d::Zero();      ///< path centre on the screen, m
  double width = 1.2;                                    ///< rectangle width / random box width, m
  double height = 0.8;                                   ///< rectangle height / random box height, m
  double radius = 0.4;                                   ///< circle radius, m
  double duration = 120.0;                               ///< random path: length covered (s of travel)
  double corner_radius = 0.0;  ///< random path: each vertex rounded by a circular arc of this radius (m; 0: sharp)
};

/// Position of the target on the screen plane (screen frame x right, y down, metres). The
/// rectangle starts at its top-left corner and runs clockwise as seen on the screen; the circle
/// starts at angle 0; the random path is a polyline through uniform random waypoints in the box.
/// With corner_radius r > 0 (random path) each vertex is replaced by the circular arc of radius r tangent
/// to both segments (tangent length r tan(φ/2), φ the turn), so the heading is continuous and the
/// curvature is 1/r on the arcs: waypoints whose turn would not fit within half of both segments are
/// drawn again (so the turns are gentler than on the polyline), and segments are at least 2r long.
class ScreenPath {
public:
  /// rng is used only by the random path (drawn at construction).
  ScreenPath(const ScreenPathParams& params, core::Rng& rng);
  /// Target position at time t (s) on the screen plane (screen frame, m).
  Eigen::Vector2d position(double t) const;
  /// Target velocity at time t (s) on the screen plane (screen frame, m/s).
  Eigen::Vector2d velocity(double t) const;
  /// Times in (0, t_end] at which the target passes a vertex of the polyline (its corners); empty for the
  /// circle; with rounded corners, the times at the middle of each arc.
  std::vector<double> cornerTimes(double t_end) const;
  /// The parameters in use.
  const ScreenPathParams& params() const { return params_; }

private:
  Eigen::Vector2d atArcLength(double s) const;
  ScreenPathParams params_;
  std::vector<Eigen::Vector2d> vertices_;  ///< closed (rectangle) or open (random) polyline
  std::vector<double> cumulative_;         ///< arc length at each vertex
  struct Piece {                           ///< rounded random path: straight pieces and arcs
    double s0 = 0.0, length = 0.0;         ///< arc length at the start, length
    Eigen::Vector2d p0 = Eigen::Vector2d::Zero(), dir = Eigen::Vector2d::Zero();  ///< straight piece
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();                             ///< arc
    double radius = 0.0, a0 = 0.0, sign = 0.0;  ///< arc: angle at the start about the centre, +1 left / −1 right
  };
  std::vector<Piece> pieces_;              ///< empty: the polyline vertices_ is the path
  void roundCorners();                     ///< pieces_ from vertices_ and corner_radius
};

// ----------------------------------------------------------------------------------------------
// Ground target ([K]).

/// Speed and turn-rate profile of the ground target ([K]'s two test profiles).
enum class GroundProfile {
  Capture,     ///< v = 0.30 (cos(0.01k) + 1) + ξv m/s, ω = 0.7 sin(0.03k + π/1.5) + ξω (var 2 cm²/s², 0.1)
  FilterTest,  ///< v = 0.15 (sin(0.02k) + 1) + ξv,  ω = 0.7 cos(0.01k) + ξω  (var 3 cm²/s², 0.1)
};

/// Profile, start pose, duration and integration of the simulated ground target ([K]).
struct GroundTargetParams {
  GroundProfile profile = GroundProfile::Capture;  ///< which of [K]'s profiles drives the target
  double profile_period = 0.1;                                  ///< s per profile index k ([K]: vision period)
  Eigen::Vector2d start = Eigen::Vector2d(-2.5, 3.0);           ///< m ([K]: (-250, 300) cm)
  double heading = 0.0;                                         ///< initial θ, rad
  double duration = 60.0;                                       ///< precomputed span, s
  double substep = 0.01;                                        ///< integration step, s
  bool noise = true;                                            ///< add ξv, ξω (else the nominal profile)
};

/// State of the ground target on the floor (world frame).
struct GroundState {
  double x = 0.0,      ///< position x, world frame, m
         y = 0.0,      ///< position y, world frame, m
         theta = 0.0;  ///< heading from the world x axis, rad
  double v = 0.0,      ///< forward speed, m/s
         omega = 0.0;  ///< turn rate, rad/s
};

/// A unicycle target on the floor driven by [K]'s profiles, precomputed over [0, duration] (seeded noise).
class GroundTarget {
public:
  /// Precomputes the trajectory; rng draws the profile noise ξv, ξω when params.noise.
  GroundTarget(const GroundTargetParams& params, core::Rng& rng);
  /// State at t in [0, duration] (exact within a sub-step: the unicycle is re-integrated from the
  /// knot before t with the constant (v, ω) of that profile step).
  GroundState state(double t) const;
  /// Nominal profile (without ξ) at index k, SI units.
  static Eigen::Vector2d nominal(GroundProfile profile, double k);
  /// The parameters in use.
  const GroundTargetParams& params() const { return params_; }

private:
  GroundTargetParams params_;
  std::vector<GroundState> knots_;        ///< every substep
  std::vector<Eigen::Vector2d> inputs_;   ///< (v, ω) per profile index
};

}  // namespace viewline::sim
