// A contact between the hand and the object (or the table), as the simulator reports it
// and the grasp-quality metrics consume it.
#pragma once

#include <vector>

#include "bayesgrasp/geometry/mesh.hpp"

namespace bayesgrasp {

struct Contact {
  Vec3 point = Vec3::Zero();   // world frame, on the object's surface (m)
  Vec3 normal = Vec3::UnitZ(); // world frame, unit, the object's outward surface normal
  int link = -1;               // index of the hand link in contact (0 = palm)
  double penetration = 0.0;    // >= 0, depth of overlap (m); 0 for touching within tolerance
  bool on_table = false;       // true if the contact is with the table, not the object
  int triangle = -1;           // the object's triangle nearest to the link (-1 for the table)
};

using Contacts = std::vector<Contact>;

}  // namespace bayesgrasp
