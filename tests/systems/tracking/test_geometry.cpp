// Exact recovery on noise-free synthetic data and clear errors on degenerate input for the
// camera model, two-view geometry, triangulation and registration.
#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <catch2/catch.hpp>
#include "synthetic.hpp"
#include "systems/tracking/epipolar.hpp"
#include "systems/tracking/registration.hpp"
#include "systems/tracking/triangulation.hpp"

using namespace fire;
using namespace fire::tracking;
using namespace fire::tracking::test;

namespace {

Eigen::Matrix3d skew(const Vec3& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Eigen::Matrix3d true_fundamental(const Rig& rig) {
  const Eigen::Matrix3d F = camera_matrix(rig.cam1.K).inverse().transpose() * skew(rig.cam1.t) *
                            rig.cam1.R * camera_matrix(rig.cam0.K).inverse();
  return F / F.norm();
}

double up_to_sign(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return std::min((A - B).norm(), (A + B).norm());
}

Rig pinhole_rig() {
  Intrinsics K0 = true_intrinsics(0), K1 = true_intrinsics(1);
  K0.k1 = K1.k1 = 0;
  return accuracy_rig(K0, K1);
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

TEST_CASE("camera: projection, ray and undistortion invert each other", "[camera]") {
  Intrinsics K = true_intrinsics(0);
  K.k2 = 0.02;
  const Rig rig = accuracy_rig(K, true_intrinsics(1));
  std::mt19937_64 rng(1);
  for (const Vec3& X : visible_points(rig, 200, rng)) {
    for (const Camera* c : {&rig.cam0, &rig.cam1}) {
      const Vec2 px = c->project(X);
      const Vec3 dir = c->ray(px);
      const Vec3 expected = (X - c->centre()).normalized();
      REQUIRE((dir - expected).norm() < 1e-12);
      const Vec3 Xc = c->R * X + c->t;
      REQUIRE((c->undistort_normalized(px) - Xc.head<2>() / Xc.z()).norm() < 1e-13);
      REQUIRE(c->depth(X) == Approx(Xc.z()).epsilon(1e-14));
    }
  }
  const Intrinsics nominal = wiimote_nominal_intrinsics();
  CHECK(nominal.fx == 1330.0);
  CHECK(nominal.cx == 512.0);
  CHECK(nominal.cy == 384.0);
}

TEST_CASE("fundamental matrix: exact correspondences recover F to 1e-9", "[epipolar]") {
  const Rig rig = pinhole_rig();
  std::mt19937_64 rng(2);
  for (int count : {8, 9, 50, 500}) {
    std::vector<Vec2> x0, x1;
    for (const Vec3& X : visible_points(rig, count, rng)) {
      x0.push_back(rig.cam0.project(X));
      x1.push_back(rig.cam1.project(X));
    }
    const Result<Eigen::Matrix3d> F = fundamental_8point(x0, x1);
    REQUIRE(F.ok());
    CHECK(up_to_sign(*F, true_fundamental(rig)) < 1e-9);
    CHECK(std::abs(F->norm() - 1.0) < 1e-12);
    CHECK(std::abs(F->determinant()) < 1e-15);
    CHECK(mean_epipolar_distance(*F, x0, x1) < 1e-7);
  }
}

TEST_CASE("pose: exact data recovers R and unit t to 1e-9", "[epipolar]") {
  const Rig rig = pinhole_rig();
  std::mt19937_64 rng(3);
  std::vector<Vec2> x0, x1, n0, n1;
  for (const Vec3& X : visible_points(rig, 60, rng)) {
    x0.push_back(rig.cam0.project(X));
    x1.push_back(rig.cam1.project(X));
    n0.push_back(rig.cam0.undistort_normalized(x0.back()));
    n1.push_back(rig.cam1.undistort_normalized(x1.back()));
  }
  const Result<Eigen::Matrix3d> F = fundamental_8point(x0, x1);
  REQUIRE(F.ok());
  const Eigen::Matrix3d E = essential_from_fundamental(*F, rig.cam0.K, rig.cam1.K);
  const Eigen::Matrix3d E_true = skew(rig.cam1.t) * rig.cam1.R;
  CHECK(up_to_sign(E, E_true / E_true.norm()) < 1e-9);
  const Result<RelativePose> pose = recover_pose(E, n0, n1);
  REQUIRE(pose.ok());
  CHECK((pose->R - rig.cam1.R).norm() < 1e-9);
  CHECK((pose->t - rig.cam1.t.normalized()).norm() < 1e-9);
}

TEST_CASE("fundamental matrix and pose: degenerate input gives a clear error", "[epipolar]") {
  const Rig rig = pinhole_rig();
  std::mt19937_64 rng(4);
  std::vector<Vec2> x0, x1;
  for (const Vec3& X : visible_points(rig, 12, rng)) {
    x0.push_back(rig.cam0.project(X));
    x1.push_back(rig.cam1.project(X));
  }
  SECTION("fewer than 8 correspondences") {
    const auto F = fundamental_8point(std::span(x0).first(7), std::span(x1).first(7));
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("at least 8") != std::string::npos);
  }
  SECTION("mismatched sizes") {
    const auto F = fundamental_8point(std::span(x0).first(10), std::span(x1).first(9));
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("10 points in image 0 but 9") != std::string::npos);
  }
  SECTION("all points on a line") {
    // Points along one 3D line project onto a line in both images.
    std::vector<Vec2> l0, l1;
    for (int i = 0; i < 20; ++i) {
      const Vec3 X = rig.cube_centre + (i - 10) * 0.02 * Vec3(1, 0.3, 0.2);
      l0.push_back(rig.cam0.project(X));
      l1.push_back(rig.cam1.project(X));
    }
    const auto F = fundamental_8point(l0, l1);
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("line") != std::string::npos);
  }
  SECTION("points of one image on a line, the other general") {
    std::vector<Vec2> l0 = x0;
    for (size_t i = 0; i < l0.size(); ++i) l0[i] = Vec2(100 + 30.0 * static_cast<double>(i), 200 + 7.0 * static_cast<double>(i));
    const auto F = fundamental_8point(l0, x1);
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("image 0 lie on a line") != std::string::npos);
  }
  SECTION("all points on one plane in space (the images are related by a homography)") {
    std::vector<Vec2> p0, p1;
    for (int i = 0; i < 30; ++i) {
      const Vec3 X = rig.cube_centre + rig.cube_axes * Vec3(0.02 * (i % 6) - 0.05, 0.03 * (i / 6) - 0.06, 0.0);
      p0.push_back(rig.cam0.project(X));
      p1.push_back(rig.cam1.project(X));
    }
    const auto F = fundamental_8point(p0, p1);
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("do not determine a unique solution") != std::string::npos);
  }
  SECTION("all points the same") {
    const std::vector<Vec2> same(10, Vec2(300, 200));
    const auto F = fundamental_8point(same, std::span(x1).first(10));
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("degenerate") != std::string::npos);
  }
  SECTION("non-finite input") {
    x1[3].x() = kNaN;
    const auto F = fundamental_8point(x0, x1);
    REQUIRE_FALSE(F.ok());
    CHECK(F.error().find("not finite") != std::string::npos);
  }
  SECTION("pose: mismatched, empty, non-finite or rank-deficient E") {
    const Eigen::Matrix3d E = skew(rig.cam1.t) * rig.cam1.R;
    CHECK_FALSE(recover_pose(E, std::span(x0).first(3), std::span(x1).first(4)).ok());
    CHECK_FALSE(recover_pose(E, std::span<const Vec2>(), std::span<const Vec2>()).ok());
    Eigen::Matrix3d bad = E;
    bad(1, 1) = kNaN;
    CHECK(recover_pose(bad, x0, x1).error().find("not finite") != std::string::npos);
    CHECK(recover_pose(Eigen::Matrix3d::Zero(), x0, x1).error().find("rank") != std::string::npos);
  }
}

TEST_CASE("triangulation: exact pixels give the point to 1e-9 with every method", "[triangulation]") {
  Intrinsics K0 = true_intrinsics(0);
  K0.k2 = 0.01;
  const Rig rig = accuracy_rig(K0, true_intrinsics(1));
  std::mt19937_64 rng(5);
  for (TriangulationMethod m :
       {TriangulationMethod::ThesisLinear, TriangulationMethod::Dlt, TriangulationMethod::Optimal}) {
    for (const Vec3& X : visible_points(rig, 300, rng)) {
      const Triangulation t =
          triangulate(rig.cam0, rig.cam1, rig.cam0.project(X), rig.cam1.project(X), m);
      REQUIRE(t.accepted);
      REQUIRE((t.X - X).norm() < 1e-9);
      REQUIRE(t.reprojection_error_px < 1e-6);
    }
  }
}

TEST_CASE("triangulation: bad observations are rejected, never a crash", "[triangulation]") {
  const Rig rig = accuracy_rig(true_intrinsics(0), true_intrinsics(1));
  const Vec3 X = rig.cube_centre;
  const Vec2 p0 = rig.cam0.project(X), p1 = rig.cam1.project(X);
  for (TriangulationMethod m :
       {TriangulationMethod::ThesisLinear, TriangulationMethod::Dlt, TriangulationMethod::Optimal}) {
    CHECK_FALSE(triangulate(rig.cam0, rig.cam1, Vec2(kNaN, 3), p1, m).accepted);
    CHECK_FALSE(triangulate(rig.cam0, rig.cam1, p0, Vec2(4, std::numeric_limits<double>::infinity()), m).accepted);
    // 8 px off the epipolar line: inconsistent, beyond the 2 px threshold.
    const Triangulation off = triangulate(rig.cam0, rig.cam1, p0, p1 + Vec2(0, 8), m);
    CHECK_FALSE(off.accepted);
    CHECK(off.reprojection_error_px > 2.0);
    CHECK(triangulate(rig.cam0, rig.cam1, p0, p1 + Vec2(0, 8), m, 10.0).accepted);
    // A point behind both cameras projects to plausible pixels but must not be accepted.
    const Vec3 behind = -rig.cube_centre;
    CHECK_FALSE(triangulate(rig.cam0, rig.cam1, rig.cam0.project(behind), rig.cam1.project(behind), m).accepted);
  }
}

TEST_CASE("registration: exact points recover the rigid transform to 1e-9", "[registration]") {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int count : {3, 4, 10}) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(2.0 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    const Vec3 t(u(rng), u(rng), u(rng));
    std::vector<Vec3> measured, model;
    for (int i = 0; i < count; ++i) {
      measured.push_back(0.2 * Vec3(u(rng), u(rng), u(rng)));
      model.push_back(R * measured.back() + t);
    }
    const Result<RigidTransform> T = register_rigid(measured, model);
    REQUIRE(T.ok());
    CHECK((T->R - R).norm() < 1e-9);
    CHECK((T->t - t).norm() < 1e-9);
    CHECK(T->rms_residual < 1e-9);
    CHECK(T->R.determinant() == Approx(1.0));
  }
}

TEST_CASE("registration: residual reports the misfit, degenerate input is an error", "[registration]") {
  const std::vector<Vec3> model = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}};
  std::vector<Vec3> measured = model;
  measured[3].z() += 0.004;  // one point 4 mm off
  const Result<RigidTransform> T = register_rigid(measured, model);
  REQUIRE(T.ok());
  CHECK(T->rms_residual > 0.0005);
  CHECK(T->rms_residual < 0.004);

  CHECK(register_rigid(std::span(model).first(2), std::span(model).first(2)).error().find("at least 3") !=
        std::string::npos);
  const std::vector<Vec3> line = {{0, 0, 0}, {0.1, 0.1, 0}, {0.3, 0.3, 0}, {0.5, 0.5, 0}};
  CHECK(register_rigid(line, line).error().find("collinear") != std::string::npos);
  CHECK_FALSE(register_rigid(std::span(model).first(3), model).ok());
  measured[1].x() = kNaN;
  CHECK(register_rigid(measured, model).error().find("not finite") != std::string::npos);
}
