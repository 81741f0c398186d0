// Reading a hand file (JSON) into a HandModel; every problem names the file's field. The
// kinematics are in hand_model.cpp.
#include "bayesgrasp/hand/hand_model.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace bayesgrasp {

namespace {

using nlohmann::json;
constexpr double kDeg = M_PI / 180.0;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::invalid_argument("hand file: " + where + ": " + what);
}

const json& need(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) fail(where, std::string("missing key '") + key + "'");
  return j.at(key);
}

/// A strict object: every key one of `known`, none missing from `known` (every key is required:
/// nothing takes a default), except the keys `docs`, which may be absent: documentation, and the
/// few with a stated default (the top level's closing, a finger's roll_deg).
void exactly(const json& j, std::initializer_list<const char*> known, const std::string& where,
             std::initializer_list<const char*> docs = {}) {
  if (!j.is_object()) fail(where, "must be an object");
  auto listed = [](const std::string& k, std::initializer_list<const char*> keys) {
    return std::any_of(keys.begin(), keys.end(), [&](const char* x) { return k == x; });
  };
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (listed(it.key(), known) || listed(it.key(), docs)) continue;
    std::string names;
    for (const char* k : known) names += std::string(names.empty() ? "" : ", ") + k;
    for (const char* k : docs) names += std::string(", ") + k;
    fail(where, "unknown key '" + it.key() + "' (known: " + names + ")");
  }
  for (const char* k : known)
    if (!j.contains(k)) fail(where, std::string("missing key '") + k + "'");
}

std::string text(const json& j, const char* key, const std::string& where) {
  const json& v = need(j, key, where);
  if (!v.is_string() || v.get<std::string>().empty()) fail(where, std::string("'") + key + "' must be a non-empty string");
  return v.get<std::string>();
}

double number(const json& j, const char* key, const std::string& where) {
  const json& v = need(j, key, where);
  if (!v.is_number()) fail(where, std::string("'") + key + "' must be a number");
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(where, std::string("'") + key + "' must be finite");
  return x;
}

Vec3 vec3(const json& j, const char* key, const std::string& where) {
  const json& v = need(j, key, where);
  if (!v.is_array() || v.size() != 3) fail(where, std::string("'") + key + "' must be a list of 3 numbers");
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) fail(where, std::string("'") + key + "' must be a list of 3 numbers");
    out[i] = v[i].get<double>();
  }
  if (!out.allFinite()) fail(where, std::string("'") + key + "' must be finite");
  return out;
}

/// A convex shape from its vertices and outward triangles; refuses one that is not closed, not
/// convex or wound inwards (every vertex must lie behind every face's plane).
Shape convex_shape(const json& s, const std::string& w) {
  Shape shape;
  shape.type = Shape::Type::Convex;
  const json& v = need(s, "vertices", w);
  if (!v.is_array() || v.size() < 4) fail(w, "'vertices' must be a list of at least 4 points");
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_array() || v[i].size() != 3 || !v[i][0].is_number() || !v[i][1].is_number() || !v[i][2].is_number())
      fail(w, "vertices[" + std::to_string(i) + "] must be a list of 3 numbers");
    const Vec3 p(v[i][0].get<double>(), v[i][1].get<double>(), v[i][2].get<double>());
    if (!p.allFinite()) fail(w, "vertices[" + std::to_string(i) + "] must be finite");
    shape.vertices.push_back(p);
  }
  const json& f = need(s, "faces", w);
  if (!f.is_array() || f.size() < 4) fail(w, "'faces' must be a list of at least 4 triangles");
  const int n = static_cast<int>(shape.vertices.size());
  std::map<std::pair<int, int>, int> edges;  // directed edge -> count: closed and consistently wound
  for (size_t i = 0; i < f.size(); ++i) {
    const std::string wi = "faces[" + std::to_string(i) + "]";
    if (!f[i].is_array() || f[i].size() != 3) fail(w, wi + " must be 3 vertex indices");
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      if (!f[i][k].is_number_integer() || f[i][k].get<long long>() < 0 || f[i][k].get<long long>() >= n)
        fail(w, wi + " must be 3 vertex indices in [0, " + std::to_string(n) + ")");
      t[k] = f[i][k].get<int>();
    }
    const Vec3 nrm = (shape.vertices[t[1]] - shape.vertices[t[0]]).cross(shape.vertices[t[2]] - shape.vertices[t[0]]);
    if (!(nrm.norm() > 1e-14)) fail(w, wi + " is degenerate (zero area)");
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    shape.faces.push_back(t);
    const Vec3 u = nrm.normalized();
    shape.planes.emplace_back(u.x(), u.y(), u.z(), u.dot(shape.vertices[t[0]]));
  }
  for (const auto& [e, count] : edges)
    if (count != 1 || !edges.count({e.second, e.first}))
      fail(w, "faces do not close the shape with a consistent winding (edge " + std::to_string(e.first) + "-" +
                  std::to_string(e.second) + ")");
  double scale = 0.0;
  for (const Vec3& p : shape.vertices) shape.center += p / n;
  for (const Vec3& p : shape.vertices) scale = std::max(scale, (p - shape.center).norm());
  shape.radius = scale;
  for (size_t i = 0; i < shape.planes.size(); ++i)
    for (const Vec3& p : shape.vertices)
      if (shape.planes[i].head<3>().dot(p) - shape.planes[i][3] > 1e-9 * std::max(scale, 1e-3))
        fail(w, "not convex or wound inwards: a vertex lies outside faces[" + std::to_string(i) + "]'s plane");
  return shape;
}

std::vector<Shape> shapes(const json& j, const std::string& where) {
  std::vector<Shape> out;
  const json& arr = need(j, "shapes", where);
  if (!arr.is_array()) fail(where, "'shapes' must be a list");
  for (size_t i = 0; i < arr.size(); ++i) {
    const std::string w = where + ".shapes[" + std::to_string(i) + "]";
    const json& s = arr[i];
    const json& type = need(s, "type", w);
    Shape shape;
    if (type == "box") {
      exactly(s, {"type", "center", "half_extents"}, w);
      shape.type = Shape::Type::Box;
      shape.center = vec3(s, "center", w);
      shape.half_extents = vec3(s, "half_extents", w);
      if ((shape.half_extents.array() <= 0).any()) fail(w, "half_extents must be positive");
    } else if (type == "capsule") {
      exactly(s, {"type", "p0", "p1", "radius"}, w);
      shape.type = Shape::Type::Capsule;
      shape.p0 = vec3(s, "p0", w);
      shape.p1 = vec3(s, "p1", w);
      shape.radius = number(s, "radius", w);
      if (!(shape.radius > 0)) fail(w, "radius must be positive");
    } else if (type == "convex") {
      exactly(s, {"type", "vertices", "faces"}, w);
      shape = convex_shape(s, w);
    } else {
      fail(w, "unknown shape type (expected 'box', 'capsule' or 'convex')");
    }
    out.push_back(shape);
  }
  return out;
}

/// One phalanx of a finger from its JSON object (`where` names it in errors). A revolute joint's
/// limits and offset are in degrees and its motor's strength a torque (N m); a prismatic
/// joint's in metres and a force (N).
Phalanx parse_phalanx(const json& j, size_t p, const std::string& where) {
  const json& kind = need(j, "joint", where);
  Phalanx phalanx;
  double unit = kDeg;
  const char* effort = "torque_nm";
  if (kind == "revolute") {
    exactly(j, {"name", "joint", "length", "lower_deg", "upper_deg", "offset_deg", "ratio", "torque_nm", "shapes"}, where);
  } else if (kind == "prismatic") {
    exactly(j, {"name", "joint", "length", "lower_m", "upper_m", "offset_m", "ratio", "force_n", "shapes"}, where);
    phalanx.prismatic = true;
    unit = 1.0;
    effort = "force_n";
  } else {
    fail(where, "'joint' must be 'revolute' or 'prismatic'");
  }
  const bool m = phalanx.prismatic;
  phalanx.name = text(j, "name", where);
  phalanx.length = number(j, "length", where);
  if (!(phalanx.length > 0)) fail(where, "length must be positive");
  phalanx.lower = number(j, m ? "lower_m" : "lower_deg", where) * unit;
  phalanx.upper = number(j, m ? "upper_m" : "upper_deg", where) * unit;
  if (phalanx.lower > phalanx.upper) fail(where, m ? "lower_m > upper_m" : "lower_deg > upper_deg");
  phalanx.offset = number(j, m ? "offset_m" : "offset_deg", where) * unit;
  phalanx.ratio = number(j, "ratio", where);  // its sign is checked against the closing scheme
  phalanx.torque = number(j, effort, where);
  if (!(phalanx.torque >= 0) || !std::isfinite(phalanx.torque)) fail(where, std::string(effort) + " must be >= 0 and finite");
  phalanx.shapes = shapes(j, where);
  return phalanx;
}

/// The couplings' signs against the closing scheme: breakaway needs every ratio >= 0; a linkage
/// a first ratio > 0 (the driver closes the finger) and any finite ratio after it; independent
/// every ratio > 0 (each joint's closing speed).
void check_ratios(const Finger& finger, Closing closing, const std::string& where) {
  for (size_t p = 0; p < finger.phalanges.size(); ++p) {
    const double r = finger.phalanges[p].ratio;
    const std::string w = where + ".phalanges[" + std::to_string(p) + "]";
    if (!std::isfinite(r)) fail(w, "ratio must be finite");
    if (closing == Closing::Breakaway && r < 0)
      fail(w, "ratio must be >= 0 with closing 'breakaway' (a phalanx turning against its driver, e.g. a pad "
              "kept parallel, needs \"closing\": \"linkage\")");
    if (closing == Closing::Linkage && p == 0 && !(r > 0))
      fail(w, "ratio must be > 0 for a finger's first phalanx (its driver) with closing 'linkage'");
    if (closing == Closing::Independent && !(r > 0))
      fail(w, "ratio must be > 0 with closing 'independent' (every joint closes, at its ratio's speed)");
  }
}

/// Indices into q of the joints the "fingers read" measurement uses, from their link names
/// ("finger/phalanx"); each at most once.
std::vector<int> parse_measured_joints(const json& names, const HandModel& h) {
  if (!names.is_array() || names.empty()) fail("measured_joints", "must be a non-empty list of phalanx names");
  std::vector<int> out;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string w = "measured_joints[" + std::to_string(i) + "]";
    if (!names[i].is_string()) fail(w, "must be a phalanx name 'finger/phalanx'");
    const std::string n = names[i].get<std::string>();
    int found = -1;
    for (const Finger& f : h.fingers())
      for (size_t p = 0; p < f.phalanges.size(); ++p)
        if (f.name + "/" + f.phalanges[p].name == n) found = f.first_joint + static_cast<int>(p);
    if (found < 0) fail(w, "no phalanx named '" + n + "'");
    if (std::find(out.begin(), out.end(), found) != out.end()) fail(w, "'" + n + "' listed twice");
    out.push_back(found);
  }
  return out;
}

}  // namespace

HandModel HandModel::from_json(const std::string& json_text) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::parse_error& e) {
    throw std::invalid_argument(std::string("hand file: not valid JSON: ") + e.what());
  }
  HandModel h;
  // name, geometry and actuation are required; description and frame are documentation
  exactly(root, {"name", "actuation", "palm", "spread", "fingers", "measured_joints"}, "top level",
          {"description", "frame", "closing"});
  if (root.contains("closing")) {
    const std::string c = text(root, "closing", "top level");
    if (c == "linkage") h.closing_ = Closing::Linkage;
    else if (c == "independent") h.closing_ = Closing::Independent;
    else if (c != "breakaway") fail("closing", "must be 'breakaway', 'linkage' or 'independent', got '" + c + "'");
  }
  h.name_ = text(root, "name", "top level");
  if (!root.at("actuation").is_object()) fail("actuation", "must be an object (the strength's figures and sources)");

  Link palm;
  palm.name = "palm";
  exactly(root.at("palm"), {"shapes"}, "palm");
  palm.shapes = shapes(root.at("palm"), "palm");
  h.links_.push_back(palm);

  const json& spread = root.at("spread");
  exactly(spread, {"lower_deg", "upper_deg", "default_deg"}, "spread");
  h.spread_lower_ = number(spread, "lower_deg", "spread") * kDeg;
  h.spread_upper_ = number(spread, "upper_deg", "spread") * kDeg;
  h.spread_default_ = number(spread, "default_deg", "spread") * kDeg;
  if (h.spread_lower_ > h.spread_upper_) fail("spread", "lower_deg > upper_deg");

  const json& fingers = need(root, "fingers", "top level");
  if (!fingers.is_array() || fingers.empty()) fail("fingers", "must be a non-empty list");
  int joint = 1;
  for (size_t f = 0; f < fingers.size(); ++f) {
    const std::string w = "fingers[" + std::to_string(f) + "]";
    const json& jf = fingers[f];
    exactly(jf, {"name", "base", "base_yaw_deg", "spread_sign", "knuckle", "phalanges"}, w, {"roll_deg"});
    Finger finger;
    finger.name = text(jf, "name", w);
    finger.base = vec3(jf, "base", w);
    finger.base_yaw = number(jf, "base_yaw_deg", w) * kDeg;
    finger.spread_sign = number(jf, "spread_sign", w);
    if (jf.contains("roll_deg")) {
      finger.roll = number(jf, "roll_deg", w) * kDeg;
      if (std::abs(finger.roll) >= M_PI / 2) fail(w, "roll_deg must lie in (-90, 90)");
    }
    {
      const json& k = jf.at("knuckle");
      exactly(k, {"length", "shapes"}, w + ".knuckle");
      finger.knuckle_length = number(k, "length", w + ".knuckle");
      if (finger.knuckle_length < 0) fail(w + ".knuckle", "length must be >= 0");
      finger.knuckle_shapes = shapes(k, w + ".knuckle");
    }
    if (!finger.knuckle_shapes.empty()) {
      Link link;
      link.name = finger.name + "/knuckle";
      link.finger = static_cast<int>(f);
      link.shapes = finger.knuckle_shapes;
      finger.knuckle_link = static_cast<int>(h.links_.size());
      h.links_.push_back(link);
    }
    const json& ph = need(jf, "phalanges", w);
    if (!ph.is_array() || ph.empty()) fail(w, "'phalanges' must be a non-empty list");
    finger.first_joint = joint;
    for (size_t p = 0; p < ph.size(); ++p) {
      const std::string wp = w + ".phalanges[" + std::to_string(p) + "]";
      Phalanx phalanx = parse_phalanx(ph[p], p, wp);
      Link link;
      link.name = finger.name + "/" + phalanx.name;
      for (const Link& other : h.links_)  // link names are how results and the viewer name links
        if (other.name == link.name)
          fail(wp, "its link name '" + link.name + "' is taken (a finger's knuckle is '<finger>/knuckle'; phalanx "
                   "names must differ from it and from each other)");
      link.finger = static_cast<int>(f);
      link.phalanx = static_cast<int>(p);
      link.shapes = phalanx.shapes;
      phalanx.link = static_cast<int>(h.links_.size());
      h.links_.push_back(link);
      finger.phalanges.push_back(phalanx);
      ++joint;
    }
    for (const Phalanx& p : finger.phalanges)
      if (p.prismatic && finger.phalanges.size() != 1)
        fail(w, "a prismatic phalanx must be its finger's only phalanx (a jaw)");
    check_ratios(finger, h.closing_, w);
    if (finger.roll != 0.0 && finger.phalanges.front().prismatic) fail(w, "a jaw has no roll_deg");
    h.fingers_.push_back(finger);
  }
  h.num_joints_ = joint;
  h.measured_joints_ = parse_measured_joints(root.at("measured_joints"), h);
  return h;
}

HandModel HandModel::from_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("hand file: cannot open '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return from_json(ss.str());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(e.what()) + " (in '" + path + "')");
  }
}

}  // namespace bayesgrasp
