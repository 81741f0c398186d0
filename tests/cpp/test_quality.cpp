// Grasp wrench space, Ferrari-Canny epsilon and GWS volume, against hand-derived values and
// an independent brute-force facet enumeration.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>

#include "bayesgrasp/quality/wrench_space.hpp"

using namespace bayesgrasp;

namespace {

Contact make_contact(const Vec3& p, const Vec3& n, bool table = false) {
  Contact c;
  c.point = p;
  c.normal = n.normalized();
  c.on_table = table;
  return c;
}

// Independent check of epsilon: enumerate every 6-subset of the wrenches, take the hyperplane
// through it (if the subset is affinely independent), keep it if all wrenches lie on one
// side (a supporting hyperplane, i.e. the plane of a facet), and return the minimum over
// those planes of the signed distance from the origin (positive on the hull's side).
// Exponential, fine for up to ~24 wrenches.
double brute_force_epsilon(const Wrenches& W) {
  const int n = static_cast<int>(W.rows());
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> idx(6);
  for (int i = 0; i < 6; ++i) idx[i] = i;
  while (true) {
    Eigen::Matrix<double, 6, 7> A;
    for (int r = 0; r < 6; ++r) {
      A.row(r).head<6>() = W.row(idx[r]);
      A(r, 6) = 1.0;
    }
    Eigen::FullPivLU<Eigen::Matrix<double, 6, 7>> lu(A);
    lu.setThreshold(1e-10);
    if (lu.rank() == 6) {
      Eigen::Matrix<double, 7, 1> k = lu.kernel().col(0);
      const double nn = k.head<6>().norm();
      Eigen::Matrix<double, 6, 1> normal = k.head<6>() / nn;
      double offset = k(6) / nn;  // plane: normal . x + offset = 0
      double lo = 0, hi = 0;
      for (int r = 0; r < n; ++r) {
        const double s = W.row(r).dot(normal) + offset;
        lo = std::min(lo, s);
        hi = std::max(hi, s);
      }
      const double tol = 1e-9;
      if (hi <= tol || lo >= -tol) {
        if (lo >= -tol) offset = -offset;  // orient so the wrenches satisfy normal.x + offset <= 0
        best = std::min(best, -offset);
      }
    }
    int i = 5;
    while (i >= 0 && idx[i] == n - 6 + i) --i;
    if (i < 0) break;
    ++idx[i];
    for (int j = i + 1; j < 6; ++j) idx[j] = idx[j - 1] + 1;
  }
  return best;
}

// Twelve frictionless contacts on the faces of a cube of half-size a centred at the origin,
// two per face, offset by +-b along a second axis (+-x faces along z, +-y faces along x,
// +-z faces along y).
Contacts twelve_contacts(double a, double b) {
  Contacts cs;
  for (int s : {1, -1})
    for (int t : {1, -1}) {
      cs.push_back(make_contact(Vec3(s * a, 0, t * b), Vec3(s, 0, 0)));
      cs.push_back(make_contact(Vec3(t * b, s * a, 0), Vec3(0, s, 0)));
      cs.push_back(make_contact(Vec3(0, t * b, s * a), Vec3(0, 0, s)));
    }
  return cs;
}

// Contacts at the centres of the six faces of a cube of half-size a centred at the origin.
Contacts face_centre_contacts(double a) {
  Contacts cs;
  for (int k = 0; k < 3; ++k)
    for (int s : {1, -1}) {
      Vec3 e = Vec3::Zero();
      e[k] = s;
      cs.push_back(make_contact(a * e, e));
    }
  return cs;
}

// Random contacts on an ellipsoid (semi-axes 4, 3, 2 cm) around `centre`.
Contacts ellipsoid_contacts(int n, std::mt19937& rng, const Vec3& centre) {
  std::normal_distribution<double> g(0.0, 1.0);
  const Vec3 axes(0.04, 0.03, 0.02);
  Contacts cs;
  for (int i = 0; i < n; ++i) {
    const Vec3 u = Vec3(g(rng), g(rng), g(rng)).normalized();
    const Vec3 p = axes.cwiseProduct(u);
    const Vec3 nrm = p.cwiseQuotient(axes.cwiseProduct(axes)).normalized();
    cs.push_back(make_contact(centre + p, nrm));
  }
  return cs;
}

}  // namespace

// Frictionless twelve-contact grasp. Contact on the +x face at (a, 0, +-b) pushes with
// f = -e_x and torque (p x f)/rho = (0, -+b/rho, 0); on the -x face, f = +e_x and torque
// (0, +-b/rho, 0). So the +-x contacts give the four wrenches (f_x, tau_y) = (+-1, +-beta),
// beta = b/rho, all sign pairs: a rectangle [-1,1] x [-beta,beta] in the (f_x, tau_y)
// plane. Likewise the +-y contacts fill (f_y, tau_z) and the +-z contacts (f_z, tau_x). The
// GWS is the convex hull of three rectangles in orthogonal planes, their "free sum". Its
// facets are {x : sum_k a_k . x_k = 1} with a_k a facet normal of rectangle k scaled to
// offset 1, i.e. a_k in {(+-1, 0), (0, +-1/beta)}; the distance of such a facet from the
// origin is 1/|a| = 1/sqrt(sum_k |a_k|^2), smallest when every |a_k| = max(1, 1/beta):
//     epsilon = min(1, beta) / sqrt(3).
// Volume of a free sum of P in R^p and Q in R^q (origin inside both) is
// p! q! / (p+q)! vol(P) vol(Q); three rectangles of area 4 beta give
//     volume = 2! 2! 2! / 6! (4 beta)^3 = 512 beta^3 / 720.
TEST(QualityAnalytic, TwelveFrictionlessContactsOnACube) {
  const double a = 0.05, b = 0.02;
  const Contacts cs = twelve_contacts(a, b);
  QualityParams prm;
  prm.mu = 0.0;
  for (double rho : {a * std::sqrt(3.0), 0.01}) {  // beta = 0.2309 and beta = 2
    const double beta = b / rho;
    const GraspQuality q = grasp_quality(cs, Vec3::Zero(), rho, prm);
    EXPECT_TRUE(q.hull_ok);
    EXPECT_EQ(q.n_contacts, 12);
    EXPECT_EQ(q.n_wrenches, 12);
    EXPECT_NEAR(q.epsilon, std::min(1.0, beta) / std::sqrt(3.0), 1e-9) << "rho " << rho;
    EXPECT_NEAR(q.volume, 512.0 * beta * beta * beta / 720.0, 1e-9 * std::max(1.0, beta * beta * beta));
  }
}

// The same contacts at the face centres: with mu = 0 every force passes through the
// centre of mass, no torque can be applied, the wrenches span only the 3-D force space:
// no force closure, epsilon = volume = 0.
// With friction and a 4-edge cone (edges along the cube's axes), the contact on the +x face
// at (a,0,0) has the edges f = (-1, +-mu, 0) with torque (p x f)/rho = (0, 0, +-gamma) and
// f = (-1, 0, +-mu) with torque (0, -+gamma, 0), gamma = a mu / rho; every wrench has one
// force component of magnitude 1, at most one more of magnitude mu, and at most one torque
// component, of magnitude gamma. Two directions bound epsilon from above:
//  * u = (0,0,0, 1,1,1)/sqrt(3) (pure torque): u . w <= gamma/sqrt(3) for every wrench;
//  * u = (0,0,gamma, 0,0,-1)/sqrt(1+gamma^2): the wrenches with f_z = +-1 have tau_z = 0,
//    those with tau_z = +-gamma have f_z = 0, so u . w <= gamma/sqrt(1+gamma^2).
// The hull's facets attain the smaller bound (the brute-force enumeration below confirms
// it for these sets), so
//     epsilon = min(gamma/sqrt(3), gamma/sqrt(1+gamma^2)).
TEST(QualityAnalytic, FaceCentreGraspFrictionlessVersusFriction) {
  const double a = 0.05;
  const Contacts cs = face_centre_contacts(a);
  QualityParams frictionless;
  frictionless.mu = 0.0;
  const GraspQuality q0 = grasp_quality(cs, Vec3::Zero(), a * std::sqrt(3.0), frictionless);
  EXPECT_EQ(q0.epsilon, 0.0);
  EXPECT_EQ(q0.volume, 0.0);
  EXPECT_FALSE(q0.hull_ok);

  for (double mu : {0.2, 0.5, 1.0}) {
    for (double rho : {a, a * std::sqrt(3.0), 0.3 * a}) {
      QualityParams prm;
      prm.mu = mu;
      prm.n_edges = 4;
      const double gamma = a * mu / rho;
      const double expected = std::min(gamma / std::sqrt(3.0), gamma / std::sqrt(1.0 + gamma * gamma));
      const GraspQuality q = grasp_quality(cs, Vec3::Zero(), rho, prm);
      EXPECT_TRUE(q.hull_ok);
      EXPECT_EQ(q.n_wrenches, 24);
      EXPECT_NEAR(q.epsilon, expected, 1e-9) << "mu " << mu << " rho " << rho;
      EXPECT_GT(q.volume, 0.0);
      if (mu == 0.5)  // 134,596 subsets each: once per rho is enough
        EXPECT_NEAR(brute_force_epsilon(contact_wrenches(cs, Vec3::Zero(), rho, prm)), expected, 1e-9);
    }
  }
}

// A 6-simplex: epsilon and volume from linear algebra alone (brute-force facets and
// |det| / 6!), independent of Qhull.
TEST(QualityAnalytic, SimplexHullAgainstDeterminant) {
  Wrenches W(7, 6);
  W.topRows<6>() = Eigen::Matrix<double, 6, 6>::Identity();
  W.row(6).setConstant(-0.5);
  W.row(2) *= 2.0;
  const GraspQuality q = hull_quality(W);
  Eigen::Matrix<double, 6, 6> D;
  for (int i = 0; i < 6; ++i) D.row(i) = W.row(i) - W.row(6);
  EXPECT_NEAR(q.volume, std::abs(D.determinant()) / 720.0, 1e-12);
  // The facet through e_1..e_6 (e_3 scaled by 2): x1 + x2 + x3/2 + x4 + x5 + x6 = 1, at
  // distance 1/sqrt(5.25) = 0.4364; the others are nearer; compare with brute force.
  const double bf = brute_force_epsilon(W);
  EXPECT_NEAR(q.epsilon, bf, 1e-12);
  EXPECT_LT(q.epsilon, 1.0 / std::sqrt(5.25));
  EXPECT_GT(q.epsilon, 0.0);
}

TEST(QualityBruteForce, RandomGraspsMatchFacetEnumeration) {
  std::mt19937 rng(7);
  QualityParams prm;
  prm.n_edges = 4;
  for (int trial = 0; trial < 6; ++trial) {
    prm.mu = 0.3 + 0.1 * trial;
    const Contacts cs = ellipsoid_contacts(4, rng, Vec3(0.1, -0.2, 0.3));
    const Vec3 com(0.1, -0.2, 0.3);
    const GraspQuality q = grasp_quality(cs, com, 0.04, prm);
    const double bf = brute_force_epsilon(contact_wrenches(cs, com, 0.04, prm));
    EXPECT_NEAR(q.epsilon, bf, 1e-9) << "trial " << trial;
  }
}

// Not enough contacts for force closure.
TEST(QualityNoForceClosure, OneOrTwoFrictionlessContacts) {
  QualityParams prm;
  prm.mu = 0.0;
  Contacts one{make_contact(Vec3(0.05, 0, 0), Vec3(1, 0, 0))};
  Contacts two{make_contact(Vec3(0.05, 0, 0), Vec3(1, 0, 0)), make_contact(Vec3(-0.05, 0, 0), Vec3(-1, 0, 0))};
  for (const Contacts& cs : {one, two}) {
    const GraspQuality q = grasp_quality(cs, Vec3::Zero(), 0.05, prm);
    EXPECT_LE(q.epsilon, 0.0);
    EXPECT_EQ(q.volume, 0.0);
  }
  // Six frictionless contacts can never close a 6-D wrench space (7 needed).
  Contacts six;
  std::mt19937 rng(3);
  six = ellipsoid_contacts(6, rng, Vec3::Zero());
  EXPECT_LE(grasp_quality(six, Vec3::Zero(), 0.04, prm).epsilon, 0.0);
}

// Two antipodal point contacts with friction cannot resist a torque about the line
// through them: every wrench has zero torque about that axis, the GWS is 5-D, epsilon 0.
// Three collinear contacts: the same.
TEST(QualityNoForceClosure, AntipodalAndCollinearWithFriction) {
  QualityParams prm;
  prm.mu = 0.8;
  Contacts two{make_contact(Vec3(0.03, 0.01, 0), Vec3(1, 0, 0)),
               make_contact(Vec3(-0.03, 0.01, 0), Vec3(-1, 0, 0))};
  GraspQuality q = grasp_quality(two, Vec3::Zero(), 0.05, prm);
  EXPECT_EQ(q.epsilon, 0.0);
  EXPECT_EQ(q.volume, 0.0);
  EXPECT_FALSE(q.hull_ok);
  Contacts three = two;
  three.push_back(make_contact(Vec3(0.0, 0.01, 0), Vec3(0, 1, 0)));  // on the same line
  q = grasp_quality(three, Vec3::Zero(), 0.05, prm);
  EXPECT_LE(q.epsilon, 0.0);
  EXPECT_EQ(q.volume, 0.0);
}

// Contacts only on the top and +x faces: every force has f_x + f_z < 0 (mu < 1), so the
// origin is outside a full-dimensional GWS: epsilon < 0 (not an error), volume > 0.
TEST(QualityNoForceClosure, OriginOutsideGivesNegativeEpsilon) {
  QualityParams prm;
  prm.mu = 0.5;
  Contacts cs{make_contact(Vec3(0.01, 0.02, 0.05), Vec3(0, 0, 1)), make_contact(Vec3(-0.02, -0.01, 0.05), Vec3(0, 0, 1)),
              make_contact(Vec3(0.05, 0.02, 0.01), Vec3(1, 0, 0)), make_contact(Vec3(0.05, -0.02, -0.02), Vec3(1, 0, 0))};
  const GraspQuality q = grasp_quality(cs, Vec3::Zero(), 0.0866, prm);
  EXPECT_TRUE(q.hull_ok);
  EXPECT_LT(q.epsilon, 0.0);
  EXPECT_GT(q.volume, 0.0);
}

TEST(QualityInvariance, RigidMotionOfTheWholeGrasp) {
  std::mt19937 rng(11);
  const Vec3 com(0.01, -0.02, 0.005);
  int closed = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const Contacts cs = ellipsoid_contacts(5, rng, com);
    const GraspQuality q = grasp_quality(cs, com, 0.045);
    closed += q.epsilon > 0.0;
    Iso3 T = Iso3::Identity();
    T.linear() = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    T.translation() = Vec3(0.3, -1.2, 0.7);
    Contacts moved = cs;
    for (Contact& c : moved) {
      c.point = T * c.point;
      c.normal = T.linear() * c.normal;
    }
    const GraspQuality qm = grasp_quality(moved, T * com, 0.045);
    EXPECT_NEAR(qm.epsilon, q.epsilon, 1e-9);
    EXPECT_NEAR(qm.volume, q.volume, 1e-9 * q.volume);
  }
  EXPECT_GE(closed, 3);  // positive and negative epsilons alike are invariant
}

TEST(QualityBehaviour, TableContactsAreIgnoredAndMoreFrictionHelps) {
  std::mt19937 rng(5);
  const Contacts cs = ellipsoid_contacts(5, rng, Vec3::Zero());
  Contacts with_table = cs;
  with_table.push_back(make_contact(Vec3(0, 0, -0.02), Vec3(0, 0, -1), true));
  const GraspQuality a = grasp_quality(cs, Vec3::Zero(), 0.04);
  const GraspQuality b = grasp_quality(with_table, Vec3::Zero(), 0.04);
  EXPECT_EQ(a.epsilon, b.epsilon);
  EXPECT_EQ(a.volume, b.volume);
  EXPECT_EQ(b.n_contacts, 5);
  // Each friction cone of mu2 > mu1 contains the one of mu1 (same unit normal component),
  // so the hull grows: epsilon and volume do not decrease.
  QualityParams lo, hi;
  lo.mu = 0.3;
  hi.mu = 0.6;
  const GraspQuality ql = grasp_quality(cs, Vec3::Zero(), 0.04, lo);
  const GraspQuality qh = grasp_quality(cs, Vec3::Zero(), 0.04, hi);
  EXPECT_GE(qh.epsilon, ql.epsilon);
  EXPECT_GT(qh.volume, ql.volume);
}

TEST(QualityBatch, ThreadedBatchEqualsSerial) {
  std::mt19937 rng(21);
  std::vector<Contacts> grasps;
  for (int i = 0; i < 40; ++i) grasps.push_back(ellipsoid_contacts(2 + i % 6, rng, Vec3::Zero()));
  const auto batch = grasp_quality_batch(grasps, Vec3::Zero(), 0.04, {}, 2);
  ASSERT_EQ(batch.size(), grasps.size());
  int closed = 0;
  for (size_t i = 0; i < grasps.size(); ++i) {
    const GraspQuality s = grasp_quality(grasps[i], Vec3::Zero(), 0.04);
    EXPECT_EQ(batch[i].epsilon, s.epsilon) << i;
    EXPECT_EQ(batch[i].volume, s.volume) << i;
    closed += s.epsilon > 0;
  }
  EXPECT_GT(closed, 5);  // the batch has force-closure and degenerate grasps alike
  EXPECT_LT(closed, 40);
}

TEST(QualityInput, BadParametersThrow) {
  const Contacts cs = face_centre_contacts(0.05);
  QualityParams p;
  p.mu = -0.1;
  EXPECT_THROW(grasp_quality(cs, Vec3::Zero(), 0.05, p), std::invalid_argument);
  p.mu = 0.5;
  p.n_edges = 2;
  EXPECT_THROW(grasp_quality(cs, Vec3::Zero(), 0.05, p), std::invalid_argument);
  EXPECT_THROW(grasp_quality(cs, Vec3::Zero(), 0.0, {}), std::invalid_argument);
  EXPECT_THROW(grasp_quality(cs, Vec3(NAN, 0, 0), 0.05, {}), std::invalid_argument);
  Contacts bad = cs;
  bad[0].normal.setZero();
  EXPECT_THROW(grasp_quality(bad, Vec3::Zero(), 0.05, {}), std::invalid_argument);
  EXPECT_THROW(grasp_quality_batch({cs, bad}, Vec3::Zero(), 0.05, {}, 2), std::invalid_argument);
  EXPECT_EQ(grasp_quality({}, Vec3::Zero(), 0.05).epsilon, 0.0);  // no contacts: not an error
}
