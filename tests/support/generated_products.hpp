#pragma once
// Products made in code, at random from a seed, for property tests of planning: posts with
// tenons in a beam's mortises (and a beam over them), pegs in a plate with a cover, stacked
// blocks. One-piece concave meshes as CAD exports write them, in metres, every part in the
// product's frame where it stands finished; links between the parts that touch.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "twin/geometry/product_loader.hpp"

namespace test {

// A prism along y of rectangular sections centred on the y axis, one on the next:
// (y0, y1, half x, half z), metres. One closed piece.
inline sim::TriangleMesh stepped_post(const std::vector<std::array<double, 4>>& sections, const twin::Vec3& at) {
  sim::TriangleMesh m;
  std::vector<std::array<std::array<std::uint32_t, 4>, 2>> rings;
  for (const auto& [y0, y1, hx, hz] : sections) {
    std::array<std::array<std::uint32_t, 4>, 2> ring;
    for (int level = 0; level < 2; ++level) {
      const double y = level ? y1 : y0;
      const double corners[4][2] = {{-hx, -hz}, {hx, -hz}, {hx, hz}, {-hx, hz}};
      for (int k = 0; k < 4; ++k) {
        ring[level][k] = static_cast<std::uint32_t>(m.vertices.size());
        m.vertices.push_back(at + twin::Vec3(corners[k][0], y, corners[k][1]));
      }
    }
    for (int k = 0; k < 4; ++k) {
      const int j = (k + 1) % 4;
      const auto &b = ring[0], &t = ring[1];
      m.triangles.push_back({b[k], t[k], t[j]});
      m.triangles.push_back({b[k], t[j], b[j]});
    }
    rings.push_back(ring);
  }
  const auto annulus = [&](const std::array<std::uint32_t, 4>& outer, const std::array<std::uint32_t, 4>& inner, bool up) {
    for (int k = 0; k < 4; ++k) {
      const int j = (k + 1) % 4;
      if (up) {
        m.triangles.push_back({outer[k], inner[k], inner[j]});
        m.triangles.push_back({outer[k], inner[j], outer[j]});
      } else {
        m.triangles.push_back({outer[k], inner[j], inner[k]});
        m.triangles.push_back({outer[k], outer[j], inner[j]});
      }
    }
  };
  const auto &first = rings.front()[0], &last = rings.back()[1];
  m.triangles.push_back({first[0], first[2], first[3]});
  m.triangles.push_back({first[0], first[1], first[2]});
  m.triangles.push_back({last[0], last[3], last[2]});
  m.triangles.push_back({last[0], last[2], last[1]});
  for (std::size_t s = 0; s + 1 < sections.size(); ++s) {
    if (sections[s][2] >= sections[s + 1][2]) {
      annulus(rings[s][1], rings[s + 1][0], true);
    } else {
      annulus(rings[s + 1][0], rings[s][1], false);
    }
  }
  m.pieces.emplace_back();
  for (std::uint32_t i = 0; i < m.vertices.size(); ++i) {
    m.pieces.back().push_back(i);
    m.bounds.extend(m.vertices[i]);
  }
  return m;
}

// A beam along x (y from `y0`, `height` tall, `depth` across z), centred on `at`, with
// rectangular through-holes along y at (x centre, half x, half z), metres. One closed piece.
inline sim::TriangleMesh beam_with_holes(double length, double height, double depth,
                                         const std::vector<std::array<double, 3>>& holes, const twin::Vec3& at) {
  sim::TriangleMesh m;
  std::map<std::array<long long, 3>, std::uint32_t> index;
  const auto v = [&](double x, double y, double z) {
    const std::array<long long, 3> key{std::llround(x * 1e9), std::llround(y * 1e9), std::llround(z * 1e9)};
    const auto [it, fresh] = index.try_emplace(key, static_cast<std::uint32_t>(m.vertices.size()));
    if (fresh) m.vertices.push_back(at + twin::Vec3(x, y, z));
    return it->second;
  };
  const auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    m.triangles.push_back({a, b, c});
    m.triangles.push_back({a, c, d});
  };
  const double hd = depth / 2, L = length / 2;
  std::vector<double> xs{-L};
  struct Cell {
    double x0, x1, xc, hx, hz;
  };
  std::vector<Cell> cells;
  auto sorted = holes;
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [xc, hx, hz] : sorted) {
    const double half = hx + 0.001;
    xs.push_back(xc - half);
    xs.push_back(xc + half);
    cells.push_back({xc - half, xc + half, xc, hx, hz});
  }
  xs.push_back(L);
  for (const auto& side : {std::pair{height, true}, std::pair{0.0, false}}) {
    const double y = side.first;
    const bool up = side.second;  // a structured binding cannot be captured before C++20
    const auto face = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
      if (up) {
        quad(a, b, c, d);
      } else {
        quad(a, d, c, b);
      }
    };
    for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
      const double x0 = xs[i], x1 = xs[i + 1];
      const auto cell = std::find_if(cells.begin(), cells.end(), [&](const Cell& c) { return std::abs(c.x0 - x0) < 1e-12; });
      if (cell == cells.end()) {
        face(v(x0, y, hd), v(x1, y, hd), v(x1, y, -hd), v(x0, y, -hd));
        continue;
      }
      const std::uint32_t o[4] = {v(x0, y, hd), v(x1, y, hd), v(x1, y, -hd), v(x0, y, -hd)};
      const std::uint32_t n[4] = {v(cell->xc - cell->hx, y, cell->hz), v(cell->xc + cell->hx, y, cell->hz),
                                  v(cell->xc + cell->hx, y, -cell->hz), v(cell->xc - cell->hx, y, -cell->hz)};
      for (int k = 0; k < 4; ++k) face(o[k], o[(k + 1) % 4], n[(k + 1) % 4], n[k]);
    }
  }
  for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
    const double x0 = xs[i], x1 = xs[i + 1];
    quad(v(x0, 0, hd), v(x1, 0, hd), v(x1, height, hd), v(x0, height, hd));
    quad(v(x0, 0, -hd), v(x0, height, -hd), v(x1, height, -hd), v(x1, 0, -hd));
  }
  quad(v(L, 0, hd), v(L, 0, -hd), v(L, height, -hd), v(L, height, hd));
  quad(v(-L, 0, hd), v(-L, height, hd), v(-L, height, -hd), v(-L, 0, -hd));
  for (const Cell& c : cells) {
    const double corners[4][2] = {{c.xc - c.hx, c.hz}, {c.xc + c.hx, c.hz}, {c.xc + c.hx, -c.hz}, {c.xc - c.hx, -c.hz}};
    for (int k = 0; k < 4; ++k) {
      const auto& a = corners[k];
      const auto& b = corners[(k + 1) % 4];
      quad(v(a[0], 0, a[1]), v(a[0], height, a[1]), v(b[0], height, b[1]), v(b[0], 0, b[1]));
    }
  }
  m.pieces.emplace_back();
  for (std::uint32_t i = 0; i < m.vertices.size(); ++i) {
    m.pieces.back().push_back(i);
    m.bounds.extend(m.vertices[i]);
  }
  return m;
}

// A product being made: parts with meshes where they stand finished (their frame the
// product's), links between them (at the origin of both, as the meshes already stand).
class ProductMaker {
 public:
  explicit ProductMaker(std::string name) : product_{twin::Product(std::move(name), "generated.aml"), {}, {}} {}

  void part(const std::string& name, sim::TriangleMesh mesh) {
    mesh.convex = sim::is_convex(mesh);
    mesh.hull_corners = sim::hull_corners(mesh);
    sim::make_coarse_hull(mesh);
    twin::DigitalPart p;
    p.id = name;
    p.name = name;
    p.type = name;
    p.own_interfaces["origin"] = twin::Frame{twin::Vec3::Zero(), twin::Quat::Identity()};
    product_.product.add_part(std::move(p));
    product_.meshes.push_back(std::make_shared<const sim::TriangleMesh>(std::move(mesh)));
    product_.held_by.push_back(nullptr);
  }
  // `joint`: what the second part's interface declares ("" for contact); `pitch`, a screw's.
  void link(const std::string& a, const std::string& b, const std::string& joint = "", double pitch = 0) {
    if (!joint.empty()) {
      twin::Joint j;
      j.kind = *twin::joint_kind(joint);
      j.pitch = pitch;
      product_.product.parts()[*product_.product.find_part(b)].own_joints["to_" + a] = j;
    }
    for (const auto& [self, other] : {std::pair{a, b}, std::pair{b, a}}) {
      product_.product.parts()[*product_.product.find_part(self)].own_interfaces["to_" + other] =
          twin::Frame{twin::Vec3::Zero(), twin::Quat::Identity()};
    }
    product_.product.connect(a, "to_" + b, b, "to_" + a, a + "-" + b, {});
  }
  twin::LoadedProduct take() { return std::move(product_); }

 private:
  twin::LoadedProduct product_;
};

// What a generated product should come to, as far as its making says.
enum class Expect { buildable, refused, either };

struct Generated {
  twin::LoadedProduct product;
  Expect expect = Expect::either;
  std::string recipe;  // what was made, for a failure's message
};

// Posts with tenons in a beam's mortises, a beam over their top tenons and a board on that:
// the beam frame of the hold-outs, at random. A tenon as long as the beam is deep stands the
// post on the station where the beam must go first. A mortise narrower than its tenon by more
// than the tolerance makes the product unbuildable.
inline Generated posts_and_beams(std::uint32_t seed) {
  std::mt19937 rng(seed);
  const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const auto pick = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); };
  const int posts = 1 + pick(3);
  const double beam_h = uniform(0.010, 0.025), beam_d = uniform(0.015, 0.030), post_h = uniform(0.030, 0.090);
  const double spacing = uniform(0.040, 0.080), length = spacing * posts + 0.020;
  const double tx = uniform(0.0015, 0.004), tz = uniform(0.0015, 0.004);  // tenon half sizes
  const double px = std::max(tx, tz) + uniform(0.002, 0.006);             // post body half size
  const double tenon = pick(2) ? beam_h : uniform(0.004, beam_h - 0.002);  // into the beam below
  const double play[] = {0.0003, 0.0001, 0.0, -0.0008};                    // per side: negative is too tight
  const double fit = play[pick(4)];
  const bool top = pick(2);
  std::ostringstream recipe;
  recipe << "seed " << seed << ": " << posts << " posts " << post_h * 1000 << " mm, tenons " << 2 * tx * 1000 << " x "
         << 2 * tz * 1000 << " mm " << tenon * 1000 << " deep, play " << fit * 1000 << " mm, beam " << beam_h * 1000
         << " mm" << (top ? ", a top beam and a board" : "");
  ProductMaker make("posts-and-beams");
  std::vector<std::array<double, 3>> holes;
  for (int k = 0; k < posts; ++k) holes.push_back({-length / 2 + 0.010 + spacing * (k + 0.5), tx + fit, tz + fit});
  make.part("base", beam_with_holes(length, beam_h, beam_d, holes, twin::Vec3::Zero()));
  for (int k = 0; k < posts; ++k) {
    const twin::Vec3 foot(holes[k][0], beam_h - tenon, 0);
    std::vector<std::array<double, 4>> sections{{0, tenon, tx, tz}, {tenon, tenon + post_h, px, px}};
    if (top) sections.push_back({tenon + post_h, tenon + post_h + beam_h, tx, tz});
    make.part("post" + std::to_string(k), stepped_post(sections, foot));
    make.link("base", "post" + std::to_string(k));
  }
  if (top) {
    const double y = beam_h + post_h;
    make.part("top", beam_with_holes(length, beam_h, beam_d, holes, twin::Vec3(0, y, 0)));
    for (int k = 0; k < posts; ++k) make.link("post" + std::to_string(k), "top");
    make.part("board", stepped_post({{0, 0.004, length / 2, beam_d / 2 + 0.005}}, twin::Vec3(0, y + beam_h, 0)));
    make.link("top", "board");
  }
  return {make.take(), fit < -0.0004 ? Expect::refused : fit >= 0 ? Expect::buildable : Expect::either, recipe.str()};
}

// Blocks stacked at random offsets: on the one below, beside it, overhanging it, some glued
// to it. Whether each stands is gravity's to say.
inline Generated stacked_blocks(std::uint32_t seed) {
  std::mt19937 rng(seed);
  const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const int count = 2 + std::uniform_int_distribution<int>(0, 3)(rng);
  ProductMaker make("stack");
  std::ostringstream recipe;
  recipe << "seed " << seed << ": " << count << " blocks";
  double y = 0, x = 0;
  double below_half = 0;
  for (int k = 0; k < count; ++k) {
    const double hx = uniform(0.008, 0.030), hz = uniform(0.008, 0.030), h = uniform(0.005, 0.030);
    if (k > 0) x += uniform(-1.2, 1.2) * below_half;  // may overhang
    make.part("b" + std::to_string(k), stepped_post({{0, h, hx, hz}}, twin::Vec3(x, y, 0)));
    const bool glued = k > 0 && std::uniform_int_distribution<int>(0, 3)(rng) == 0;
    if (k > 0) make.link("b" + std::to_string(k - 1), "b" + std::to_string(k), glued ? "glue" : "");
    recipe << (k ? (glued ? " glued at " : " at ") : " from ") << x * 1000 << " mm";
    y += h;
    below_half = hx;
  }
  return {make.take(), Expect::either, recipe.str()};
}

// Stacked blocks whose lowest two are a subassembly: built aside, set in place as one, the
// others stacked on it after. What stood aside must stand where it is set, and the replay must
// see it so (gravity's memory of a state once left the parts' translation out, and a
// subassembly set in place was taken to stand on the station where it was built).
inline Generated stacked_on_a_subassembly(std::uint32_t seed) {
  Generated g = stacked_blocks(seed);
  for (twin::PartIndex p : {0, 1}) g.product.product.parts()[p].subassembly = "lower";
  g.recipe += "; b0 and b1 a subassembly";
  return g;
}

}  // namespace test
