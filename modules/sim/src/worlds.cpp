#include "viewline/sim/worlds.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::sim {

using core::InvalidInput;
using Eigen::Vector3d;

namespace {
Eigen::Isometry3d pose(const Eigen::Matrix3d& R, const Vector3d& t) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = R;
  m.translation() = t;
  return m;
}
}  // namespace

Scene makeRoom(const RoomParams& p, core::Rng& rng) {
  core::requirePositive(p.floor_size, "RoomParams.floor_size");
  Scene s;
  s.background_bgr = Vector3d(0.55, 0.5, 0.45);
  // Floor: seen from above; its z (normal) up.
  s.primitives.push_back(makeRectangle("", Eigen::Isometry3d::Identity(), p.floor_size, p.floor_size,
                                       Vector3d::Ones(), makeNoiseTexture(p.floor_texture, rng)));
  if (p.walls) {
    core::requirePositive(p.wall_height, "RoomParams.wall_height");
    const auto texture = makeNoiseTexture(p.wall_texture, rng);
    const double h = 0.5 * p.floor_size;
    for (int i = 0; i < 4; ++i) {
      // Wall frame: x along the wall, y down (world -z), z outwards (into the wall).
      const Eigen::Matrix3d yaw = core::rotation(Vector3d::UnitZ(), i * core::kPi / 2.0);
      Eigen::Matrix3d R;
      R.col(0) = yaw * Vector3d::UnitX();
      R.col(1) = -Vector3d::UnitZ();
      R.col(2) = yaw * Vector3d::UnitY();
      // Mirror the texture on alternate walls so that corners do not repeat the same pattern.
      if (i % 2 == 1) {
        R.col(0) = -R.col(0);
        R.col(1) = -R.col(1);
      }
      s.primitives.push_back(makeRectangle("", pose(R, yaw * Vector3d(0.0, h, 0.0) + Vector3d(0.0, 0.0, 0.5 * p.wall_height)),
                                           p.floor_size, p.wall_height, Vector3d::Ones(), texture));
    }
  }
  return s;
}

// ----------------------------------------------------------------------------------------------

BallFlightWorld::BallFlightWorld(std::vector<DragFlight> flights, Scene environment, BallAppearance ball, Lighting lighting)
    : flights_(std::move(flights)), environment_(std::move(environment)), ball_(std::move(ball)), lighting_(lighting) {
  core::requirePositive(ball_.radius, "BallAppearance.radius");
  std::sort(flights_.begin(), flights_.end(),
            [](const DragFlight& a, const DragFlight& b) { return a.startTime() < b.startTime(); });
  for (std::size_t i = 1; i < flights_.size(); ++i) {
    if (flights_[i].startTime() < flights_[i - 1].endTime()) {
      throw InvalidInput("BallFlightWorld: flights " + std::to_string(i - 1) + " and " + std::to_string(i) + " overlap in time");
    }
  }
}

const DragFlight* BallFlightWorld::flightAt(double t) const {
  for (const auto& f : flights_) {
    if (t >= f.startTime() && t <= f.endTime()) return &f;
  }
  return nullptr;
}

void BallFlightWorld::dynamicObjects(double t, std::vector<Primitive>& out) const {
  if (const DragFlight* f = flightAt(t)) out.push_back(makeSphere(ball_.name, f->state(t).p, ball_.radius, ball_.albedo_bgr));
}

// ----------------------------------------------------------------------------------------------

DartWorld::DartWorld(DragFlight flight, Scene environment, const Eigen::Isometry3d& w_M_board, Lighting lighting)
    : flight_(std::move(flight)), environment_(std::move(environment)), lighting_(lighting) {
  // Board: cork disc with a dark ring, slightly in front of the wall.
  Primitive board = makeDisc("board", w_M_board, 0.225, Vector3d(0.25, 0.45, 0.6));
  environment_.primitives.push_back(board);
  Eigen::Isometry3d inner = w_M_board;
  inner.translation() -= 0.001 * w_M_board.linear().col(2);
  environment_.primitives.push_back(makeDisc("", inner, 0.17, Vector3d(0.1, 0.1, 0.1)));
  inner.translation() -= 0.001 * w_M_board.linear().col(2);
  environment_.primitives.push_back(makeDisc("", inner, 0.1, Vector3d(0.3, 0.6, 0.75)));
}

void DartWorld::dynamicObjects(double t, std::vector<Primitive>& out) const {
  if (t < flight_.startTime() || t > flight_.endTime()) return;
  const FlightState s = flight_.state(t);
  const auto parts = makeDart("dart", dartPose(s.p, s.v));
  out.insert(out.end(), parts.begin(), parts.end());
}

// ----------------------------------------------------------------------------------------------

TableWorld::TableWorld(const TiltTable& table, Scene environment, TableAppearance appearance, Lighting lighting)
    : table_(table), environment_(std::move(environment)), look_(appearance), lighting_(lighting) {
  core::requirePositive(look_.border_width, "TableAppearance.border_width");
  core::requirePositive(look_.border_height, "TableAppearance.border_height");
  if (look_.tags) core::requirePositive(look_.tag_size, "TableAppearance.tag_size");
}

Eigen::Isometry3d TableWorld::table_M_tag(int i) const {
  const double L = table_.params().side;
  const double s_total = look_.tag_size * 10.0 / 8.0;
  const double c = 0.5 * L + look_.border_width + 0.55 * s_total;
  const double sx = (i == 1 || i == 2) ? 1.0 : -1.0;
  const double sy = (i == 2 || i == 3) ? 1.0 : -1.0;
  // Simulator tag frame (makeTag36h11): z into the table (down), x along the table x, so that the
  // code reads upright from above: rotation of π about x.
  return pose(core::rotation(Vector3d::UnitX(), core::kPi), Vector3d(sx * c, sy * c, 0.0005));
}

Eigen::Isometry3d TableWorld::table_M_vispTag(int i) const {
  // ViSP's tag frame is the simulator's turned by π about x: x along the table x, y along the
  // table y, z along the table normal (out of the tag), origin at the tag centre.
  return table_M_tag(i) * simTag_M_vispTag();
}

void TableWorld::dynamicObjects(double t, std::vector<Primitive>& out) const {
  const TiltTableState s = table_.stateAt(t);
  const Eigen::Isometry3d w_M_t = table_.tablePose(s.tilt);
  const double L = table_.params().side, bw = look_.border_width, bh = look_.border_height;
  auto at = [&](const Vector3d& p) { return w_M_t * pose(Eigen::Matrix3d::Identity(), p); };
  out.push_back(makeRectangle("table", w_M_t, L, L, look_.surface_bgr));
  const double off = 0.5 * L + 0.5 * bw;
  out.push_back(makeBox("", at(Vector3d(off, 0, 0.5 * bh - 0.003)), Vector3d(bw, L + 2 * bw, bh + 0.006), look_.border_bgr));
  out.push_back(makeBox("", at(Vector3d(-off, 0, 0.5 * bh - 0.003)), Vector3d(bw, L + 2 * bw, bh + 0.006), look_.border_bgr));
  out.push_back(makeBox("", at(Vector3d(0, off, 0.5 * bh - 0.003)), Vector3d(L, bw, bh + 0.006), look_.border_bgr));
  out.push_back(makeBox("", at(Vector3d(0, -off, 0.5 * bh - 0.003)), Vector3d(L, bw, bh + 0.006), look_.border_bgr));
  double plate = L + 2 * bw;
  if (look_.tags) {
    const double s_total = look_.tag_size * 10.0 / 8.0;
    plate = 2.0 * (0.5 * L + bw + 1.1 * s_total + 0.005);
    out.push_back(makeBox("", at(Vector3d(0, 0, -0.0005 - 0.005)), Vector3d(plate, plate, 0.01), Vector3d(0.9, 0.9, 0.9)));
    for (int i = 0; i < 4; ++i) {
      const int id = look_.first_tag_id + i;
      out.push_back(makeTag36h11("tag" + std::to_string(id), id, look_.tag_size, w_M_t * table_M_tag(i)));
    }
  } else {
    out.push_back(makeBox("", at(Vector3d(0, 0, -0.0065)), Vector3d(plate, plate, 0.012), Vector3d(0.15, 0.15, 0.15)));
  }
  const double r = table_.params().ball_radius;
  Primitive ball = makeSphere("ball", w_M_t * Vector3d(s.p.x(), s.p.y(), r), r, look_.ball_bgr);
  out.push_back(ball);
}

// ----------------------------------------------------------------------------------------------

ScreenWorld::ScreenWorld(ScreenPath path, const Eigen::Isometry3d& w_M_screen, Scene environment,
                         ScreenAppearance appearance, Lighting lighting)
    : path_(std::move(path)), w_M_screen_(w_M_screen), scene_(std::move(environment)), look_(appearance), lighting_(lighting) {
  core::requireFinite(w_M_screen.matrix(), "ScreenWorld: w_M_screen");
  Primitive screen = makeRectangle("screen", w_M_screen, look_.width, look_.height, look_.screen_bgr);
  screen.material.unlit = true;
  scene_.primitives.push_back(screen);
}

Eigen::Vector3d ScreenWorld::target_w(double t) const {
  const Eigen::Vector2d p = path_.position(t);
  return w_M_screen_ * Vector3d(p.x(), p.y(), -0.001);
}

void ScreenWorld::dynamicObjects(double t, std::vector<Primitive>& out) const {
  Eigen::Isometry3d w_M_d = w_M_screen_;
  w_M_d.translation() = target_w(t);
  Primitive disc = makeDisc("target", w_M_d, look_.disc_radius, look_.disc_bgr);
  disc.material.unlit = true;
  out.push_back(disc);
}

// ----------------------------------------------------------------------------------------------

GroundWorld::GroundWorld(GroundTarget target, Scene environment, GroundObjectAppearance appearance, Lighting lighting)
    : target_(std::move(target)), environment_(std::move(environment)), look_(appearance), lighting_(lighting) {
  for (int i = 0; i < 3; ++i) core::requirePositive(look_.extents[i], "GroundObjectAppearance.extents");
}

void GroundWorld::dynamicObjects(double t, std::vector<Primitive>& out) const {
  if (t < 0.0 || t > target_.params().duration) return;
  const GroundState s = target_.state(t);
  const Eigen::Isometry3d w_M_o =
      pose(core::rotation(Vector3d::UnitZ(), s.theta), Vector3d(s.x, s.y, 0.5 * look_.extents.z()));
  out.push_back(makeBox("target", w_M_o, look_.extents, look_.albedo_bgr));
}

}  // namespace viewline::sim
