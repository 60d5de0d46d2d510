#include "twin/planning/threads.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <numeric>

#include <Eigen/Eigenvalues>

namespace twin {
namespace {

constexpr std::size_t kFewestPoints = 12;  // an overlap sampled by fewer says nothing of its shape
constexpr int kSectors = 12;               // "all round": the overlap in at least 11 of 12 sectors
// m: the samples lie up to the overlap's depth from either surface; the shell they make is
// as thick as the overlap and this much more (sampling, tessellation)
constexpr double kShellSlack = 2e-4;
// A thread's crests or roots follow their helix at least this well for its pitch to be taken
// from them (measure_pitch's coherence; docs/performance.md has the figures of ours and the
// real set's).
constexpr double kClearWave = 0.7;
// Slices along the axis a finest pitch holds, in measure_pitch's sums.
constexpr double kSlicesAPitch = 32;

// ISO 261 coarse series: nominal diameter and pitch, mm.
constexpr std::array<std::pair<double, double>, 23> kCoarse{{{1, 0.25},  {1.2, 0.25}, {1.6, 0.35}, {2, 0.4},   {2.5, 0.45},
                                                            {3, 0.5},   {4, 0.7},    {5, 0.8},    {6, 1},     {8, 1.25},
                                                            {10, 1.5},  {12, 1.75},  {16, 2},     {20, 2.5},  {24, 3},
                                                            {30, 3.5},  {36, 4},     {42, 4.5},   {48, 5},    {52, 5},
                                                            {56, 5.5},  {60, 5.5},   {64, 6}}};

// A line the overlap may lie round.
struct Line {
  Vec3 axis = Vec3::UnitY();  // unit
  Vec3 point = Vec3::Zero();
  bool fitted = false;  // its place fitted to the overlap's points, not a part's own axis
};

// The overlap seen about a line.
struct Fit {
  Line line;
  double inner = 0, outer = 0;  // m: least and largest distance of a point from the line
  double low = 0, high = 0;     // m along the axis
  int sectors = 0;              // of kSectors round the axis, those that hold a point
};

Fit fit_about(const std::vector<Vec3>& points, const Line& line) {
  Fit fit{line, std::numeric_limits<double>::infinity(), 0, std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), 0};
  const Vec3 u = line.axis.unitOrthogonal(), v = line.axis.cross(u);
  std::array<bool, kSectors> hit{};
  for (const Vec3& p : points) {
    const Vec3 d = p - line.point;
    const double x = d.dot(u), y = d.dot(v), along = d.dot(line.axis);
    const double r = std::hypot(x, y);
    fit.inner = std::min(fit.inner, r);
    fit.outer = std::max(fit.outer, r);
    fit.low = std::min(fit.low, along);
    fit.high = std::max(fit.high, along);
    const int sector = static_cast<int>(std::floor((std::atan2(y, x) + EIGEN_PI) / (2 * EIGEN_PI) * kSectors));
    hit[static_cast<std::size_t>(std::clamp(sector, 0, kSectors - 1))] = true;
  }
  fit.sectors = static_cast<int>(std::count(hit.begin(), hit.end(), true));
  return fit;
}

// The line through the circle that fits the points best across the axis (Kasa's circle: least
// squares of x² + y² + D x + E y + F = 0, linear in D, E, F).
Line fitted_line(const std::vector<Vec3>& points, const Vec3& axis) {
  const Vec3 u = axis.unitOrthogonal(), v = axis.cross(u);
  Eigen::MatrixXd a(points.size(), 3);
  Eigen::VectorXd b(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].dot(u), y = points[i].dot(v);
    a.row(static_cast<Eigen::Index>(i)) << x, y, 1;
    b(static_cast<Eigen::Index>(i)) = -(x * x + y * y);
  }
  const Eigen::Vector3d def = a.colPivHouseholderQr().solve(b);
  return {axis, u * (-def(0) / 2) + v * (-def(1) / 2), true};
}

// Principal axes of a cloud of points (product frame) through its mean.
std::array<Line, 3> principal_lines(const std::vector<Vec3>& points) {
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Vec3& p : points) covariance += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  std::array<Line, 3> out;
  for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(k)] = {solver.eigenvectors().col(k).normalized(), mean, false};
  return out;
}

std::vector<Vec3> vertices_in_product(const LoadedProduct& product, PartIndex part) {
  std::vector<Vec3> out;
  if (!product.meshes[part]) return out;
  const Pose& pose = product.product.parts()[part].final_pose;
  for (const Vec3& v : product.meshes[part]->vertices) out.push_back(pose * v);
  return out;
}

// The lines an overlap round a shaft may lie round: a circle fitted across each of the
// overlap's principal axes and each part's frame axes (CAD models a shaft along one of them),
// and each part's own principal axes through its middle (a bolt, a leg, a nut: their threads
// may meet over a part of a turn only, too little to fit a circle to).
std::vector<Line> candidate_lines(const LoadedProduct& product, const Interference& i,
                                  const std::array<std::vector<Vec3>, 2>& vertices) {
  std::vector<Vec3> axes;
  for (const Line& l : principal_lines(i.inside)) axes.push_back(l.axis);
  for (PartIndex p : {i.part1, i.part2}) {
    const Eigen::Matrix3d rotation = product.product.parts()[p].final_pose.linear();
    for (int k = 0; k < 3; ++k) axes.push_back(rotation.col(k));
  }
  std::vector<Line> out;
  for (const Vec3& axis : axes) out.push_back(fitted_line(i.inside, axis));
  for (const auto& v : vertices) {
    if (v.size() < 4) continue;
    const auto own = principal_lines(v);
    out.insert(out.end(), own.begin(), own.end());
    // The frame's axes through the part's middle: its principal axes lean where its
    // tessellation is uneven (a thread at one end).
    for (const Vec3& axis : axes) out.push_back({axis, own.front().point, false});
  }
  return out;
}

// Whether a part's surface is a thread round the line where the overlap is: vertices over
// the overlap's length (and a pitch either side) all round, at radii a thread's depth apart
// (its roots and crests), its crests as far out all round. A plain shaft or bore has one
// radius there; a square tenon has its corners only, at radii that differ round it.
bool ridged(const std::vector<Vec3>& vertices, const Fit& fit, double pitch) {
  const double low = fit.outer - 1.2 * pitch, high = fit.outer + 0.3 * pitch;
  const Vec3 u = fit.line.axis.unitOrthogonal(), v = fit.line.axis.cross(u);
  double least = std::numeric_limits<double>::infinity(), most = 0;
  std::array<double, kSectors> crest{};  // the largest radius in each sector; 0: none there
  for (const Vec3& p : vertices) {
    const Vec3 d = p - fit.line.point;
    const double along = d.dot(fit.line.axis);
    if (along < fit.low - pitch || along > fit.high + pitch) continue;
    const double x = d.dot(u), y = d.dot(v), r = std::hypot(x, y);
    if (r < low || r > high) continue;
    least = std::min(least, r);
    most = std::max(most, r);
    const int sector = static_cast<int>(std::floor((std::atan2(y, x) + EIGEN_PI) / (2 * EIGEN_PI) * kSectors));
    double& c = crest[static_cast<std::size_t>(std::clamp(sector, 0, kSectors - 1))];
    c = std::max(c, r);
  }
  const auto [lowest, highest] = std::minmax_element(crest.begin(), crest.end());
  return *lowest > 0 && *highest - *lowest <= 0.3 * pitch + kShellSlack && most - least >= 0.3 * pitch;
}

// A thread's pitch as the part is modelled, measured on its surface near the overlap. Its
// crests (the vertices farthest from the axis, for a shaft; nearest, for a bore) and its roots
// (the other way) each lie on a helix: along = p·θ/2π + c for a right-hand thread with θ
// turning about the axis, −p·θ/2π + c for a left-hand one. The pitch is the one whose phase,
// 2π·along/p ∓ θ, those vertices share best: |sum of e^(i phase)| over them is largest there.
// The turn in the phase makes the sum small at the pitch's multiples and fractions, and for a
// ring (a plain shaft's edge). All the surface's vertices weighted by their relief are not as
// good: their flanks' vertices, unevenly many, pull the pitch (FurnitureBench's printed legs,
// 9.41 mm by hand: 8.6-8.7 so, at a coherence of 0.3; by their crests 9.3-9.8, at 0.7-0.9).
struct MeasuredPitch {
  double pitch = 0;      // m
  double coherence = 0;  // |sum| / count: near 1 for a clean thread, near 0 for none
  bool left_hand = false;
  double turns = 0;  // the thread's length measured on: the more, the sharper the pitch
  Vec3 point = Vec3::Zero();  // on the thread's axis: the centre of the circle its crests (or roots) lie on
};

// The best pitch for points (along the axis, turn about it), either hand, from `finest` to
// `coarsest`, over a span of the axis from `low` to `high`.
MeasuredPitch sharpest_helix(const std::vector<std::pair<double, double>>& points, double low, double high, double finest,
                             double coarsest) {
  // The points in thin slices along the axis, each slice's e^(∓iθ) summed (either hand);
  // what does not change along the axis (a line through the points a little off their
  // centre) taken out, or its wide peak at no pitch pulls the thread's.
  const double slice = finest / kSlicesAPitch;
  const auto slices = static_cast<std::size_t>(std::ceil((high - low) / slice)) + 1;
  std::array<std::vector<std::complex<double>>, 2> sliced;
  std::vector<double> count(slices, 0);
  for (auto& hand : sliced) hand.assign(slices, 0.0);
  for (const auto& [along, turn] : points) {
    const auto k = std::min(slices - 1, static_cast<std::size_t>(std::max(0.0, (along - low) / slice)));
    sliced[0][k] += std::polar(1.0, turn);   // right hand: phase 2π·along/p − θ
    sliced[1][k] += std::polar(1.0, -turn);  // left hand
    count[k] += 1;
  }
  const auto n = static_cast<double>(points.size());
  for (auto& hand : sliced) {
    const std::complex<double> steady = std::accumulate(hand.begin(), hand.end(), std::complex<double>(0)) / n;
    for (std::size_t k = 0; k < slices; ++k) hand[k] -= steady * count[k];
  }
  const double tau = 2 * static_cast<double>(EIGEN_PI);
  const auto strength = [&](std::size_t hand, double frequency) {
    std::complex<double> sum = 0;
    for (std::size_t k = 0; k < slices; ++k) {
      if (count[k] > 0) sum += sliced[hand][k] * std::polar(1.0, -tau * frequency * (k + 0.5) * slice);
    }
    return std::abs(sum) / n;
  };
  // Frequencies (1/p) a twentieth of a turn over the span apart, then a hundredth of that
  // about the best.
  MeasuredPitch best;
  double best_frequency = 0;
  const double step = 0.05 / (high - low);
  for (std::size_t hand = 0; hand < 2; ++hand) {
    for (double f = 1 / coarsest; f <= 1 / finest; f += step) {
      const double c = strength(hand, f);
      if (c > best.coherence) best = {1 / f, c, hand == 1}, best_frequency = f;
    }
  }
  const std::size_t hand = best.left_hand ? 1 : 0;
  for (double f = best_frequency - step; f <= best_frequency + step; f += step / 100) {
    const double c = strength(hand, f);
    if (c > best.coherence) best = {1 / f, c, best.left_hand};
  }
  const auto [first, last] = std::minmax_element(points.begin(), points.end());
  best.turns = (last->first - first->first) / best.pitch;
  return best;
}

std::optional<MeasuredPitch> measure_pitch(const std::vector<Vec3>& vertices, const Fit& fit, double guess) {
  constexpr double kFinest = 2e-4, kCoarsest = 0.012;  // m: the pitches looked for
  const double finest = std::max(kFinest, guess / 4), coarsest = std::min(kCoarsest, guess * 4);
  // The thread beyond the overlap, too: the more turns, the sharper the pitch.
  const double low = fit.low - 10 * guess, high = fit.high + 10 * guess;
  // The slices and the pitches tried both grow with the span over the finest pitch: a span
  // past this many slices (a thread metres long, from a hostile or mis-scaled model) is not
  // measured, and ISO's pitch is taken, rather than the planning stalling on it.
  constexpr double kMostSlices = 16384;  // a 30 mm thread of 2 mm pitch: about 2 000
  if ((high - low) / (finest / kSlicesAPitch) > kMostSlices) return std::nullopt;
  const Vec3 u = fit.line.axis.unitOrthogonal(), v = fit.line.axis.cross(u);
  std::vector<Vec3> samples;  // the vertices of the thread's band of radii
  for (const Vec3& p : vertices) {
    const Vec3 d = p - fit.line.point;
    const double along = d.dot(fit.line.axis);
    if (along < low || along > high) continue;
    const double r = (d - along * fit.line.axis).norm();
    if (r < fit.outer - 1.5 * guess || r > fit.outer + guess) continue;
    samples.push_back(p);
  }
  if (samples.size() < 8 * kFewestPoints) return std::nullopt;
  std::optional<MeasuredPitch> best;
  for (const bool outside : {true, false}) {
    // The crests (or roots) are the vertices within a thin shell at the extreme radius: found
    // about the overlap's line, which may be off the thread's by a part of a millimetre, then
    // again, thinner, about the circle those lie on (flanks' vertices in the shell pull the
    // pitch: FurnitureBench's legs, 9.67 mm in a shell of 0.7 mm, 9.41 in one of 0.1).
    Line axis = fit.line;
    std::vector<Vec3> edge;
    for (const double share : {0.15, 0.03}) {
      std::vector<double> radii;
      for (const Vec3& s : samples) {
        const Vec3 d = s - axis.point;
        radii.push_back((d - d.dot(axis.axis) * axis.axis).norm());
      }
      const auto [least, most] = std::minmax_element(radii.begin(), radii.end());
      const double band = share * (*most - *least);
      edge.clear();
      for (std::size_t k = 0; k < samples.size(); ++k) {
        if ((outside ? *most - radii[k] : radii[k] - *least) <= band) edge.push_back(samples[k]);
      }
      if (edge.size() < kFewestPoints) break;
      axis = fitted_line(edge, fit.line.axis);
    }
    if (edge.size() < kFewestPoints) continue;
    std::vector<std::pair<double, double>> helix;
    for (const Vec3& p : edge) {
      const Vec3 d = p - axis.point;
      helix.emplace_back(d.dot(axis.axis) + (axis.point - fit.line.point).dot(axis.axis), std::atan2(d.dot(v), d.dot(u)));
    }
    MeasuredPitch m = sharpest_helix(helix, low, high, finest, coarsest);
    m.point = axis.point;
    if (!best || m.coherence > best->coherence) best = m;
  }
  return best;
}

// How long the two parts' threads engage: where both have surface within a pitch of the
// overlap's radius, along the axis.
double engaged_length(const std::array<std::vector<Vec3>, 2>& vertices, const Fit& fit, double pitch) {
  double low = -std::numeric_limits<double>::infinity(), high = -low;
  for (const auto& part : vertices) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : part) {
      const Vec3 d = p - fit.line.point;
      const double along = d.dot(fit.line.axis);
      const double r = (d - along * fit.line.axis).norm();
      if (std::abs(r - fit.outer) > pitch) continue;
      lo = std::min(lo, along);
      hi = std::max(hi, along);
    }
    low = std::max(low, lo);
    high = std::min(high, hi);
  }
  return std::max(high - low, fit.high - fit.low);
}

const Joint* declared_screw(const Product& product, PartIndex a, PartIndex b) {
  for (std::size_t c : product.connections_of(a)) {
    const Connection& k = product.connections()[c];
    const bool between = (k.part1 == a && k.part2 == b) || (k.part1 == b && k.part2 == a);
    if (between && k.joint.kind == Joint::Kind::screw) return &k.joint;
  }
  return nullptr;
}

}  // namespace

double coarse_pitch(double diameter) {
  const double mm = diameter * 1000;
  const auto nearest = std::min_element(kCoarse.begin(), kCoarse.end(), [&](const auto& a, const auto& b) {
    return std::abs(std::log(a.first / mm)) < std::abs(std::log(b.first / mm));
  });
  return nearest->second / 1000;
}

std::optional<Thread> thread_of(const LoadedProduct& product, const Interference& interference) {
  if (interference.inside.size() < kFewestPoints) return std::nullopt;
  const Joint* declared = declared_screw(product.product, interference.part1, interference.part2);
  const std::array<std::vector<Vec3>, 2> vertices{vertices_in_product(product, interference.part1),
                                                  vertices_in_product(product, interference.part2)};
  std::optional<Thread> best;
  double thinnest = std::numeric_limits<double>::infinity();
  for (const Line& line : candidate_lines(product, interference, vertices)) {
    const Fit fit = fit_about(interference.inside, line);
    if (line.fitted && fit.sectors < kSectors - 1) continue;
    const double shell = fit.outer - fit.inner;
    if (shell >= thinnest) continue;
    const double diameter = 2 * fit.outer;
    const double guess = declared ? declared->pitch : coarse_pitch(diameter);
    // The samples lie anywhere between the threads' roots and crests (a thread's height, 0.54
    // of the pitch), and up to the overlap's depth from the nearer surface past them, which
    // on a flank (60 degrees) is twice as deep across the axis.
    if (shell > 0.6 * guess + 2 * interference.depth + kShellSlack) continue;
    // Out of phase, ISO's basic profiles overlap by at most 5/8 of the triangle's height,
    // 0.54 of the pitch.
    if (interference.depth > 0.6 * guess + kShellSlack) continue;
    if (!declared && !ridged(vertices[0], fit, guess) && !ridged(vertices[1], fit, guess)) continue;
    // Undeclared, the pitch the parts are modelled with where either's surface shows it
    // clearly (on the longer thread of the two, a bolt's rather than its nut's), else ISO's.
    std::optional<MeasuredPitch> measured;
    if (!declared) {
      for (const auto& part : vertices) {
        const auto m = measure_pitch(part, fit, guess);
        if (m && m->coherence >= kClearWave && (!measured || m->turns > measured->turns)) measured = m;
      }
    }
    const double pitch = measured ? measured->pitch : guess;
    if (measured && interference.depth > 0.6 * pitch + kShellSlack) continue;
    Thread t;
    t.part1 = interference.part1;
    t.part2 = interference.part2;
    t.axis = line.axis;
    const Vec3 through = measured ? measured->point : line.point;  // a point on the thread's axis
    t.centre = through + line.axis * ((fit.low + fit.high) / 2 - (through - line.point).dot(line.axis));
    t.diameter = diameter;
    t.depth = interference.depth;
    t.length = engaged_length(vertices, fit, pitch);
    t.pitch = pitch;
    t.declared = declared != nullptr;
    t.pitch_measured = measured.has_value();
    t.left_hand = measured && measured->left_hand;
    t.pitch_assumed = !declared && !measured;
    best = t;
    thinnest = shell;
  }
  return best;
}

std::string describe(const Product& product, const Thread& t) {
  char text[200];
  std::snprintf(text, sizeof text, "a thread of %.1f mm, %.2f mm overlap, %.1f mm engaged, pitch %.2f mm%s", t.diameter * 1000,
                t.depth * 1000, t.length * 1000, t.pitch * 1000,
                t.pitch_assumed    ? " (ISO coarse for the diameter)"
                : t.declared       ? " (as its link declares)"
                : t.left_hand      ? " (measured on the model, left-hand)"
                                   : " (measured on the model)");
  return product.parts()[t.part2].name + " in " + product.parts()[t.part1].name + ": " + text;
}

}  // namespace twin
