// Differential tests against OpenCV on identical noisy data: the 8-point fundamental matrix by
// mean epipolar distance, and optimal triangulation by 3D error against the truth.
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include <catch2/catch.hpp>
#include "synthetic.hpp"
#include "systems/tracking/epipolar.hpp"
#include "systems/tracking/triangulation.hpp"

using namespace fire;
using namespace fire::tracking;
using namespace fire::tracking::test;

namespace {

// OpenCV's optimal triangulation has no distortion model, so the rig is pinhole.
Rig pinhole_rig() {
  Intrinsics K0 = true_intrinsics(0), K1 = true_intrinsics(1);
  K0.k1 = K1.k1 = 0;
  return accuracy_rig(K0, K1);
}

std::vector<cv::Point2d> to_cv(const std::vector<Vec2>& p) {
  std::vector<cv::Point2d> out;
  for (const Vec2& q : p) out.emplace_back(q.x(), q.y());
  return out;
}

cv::Matx34d projection(const Camera& c) {
  const Eigen::Matrix3d K = camera_matrix(c.K);
  Eigen::Matrix<double, 3, 4> Rt;
  Rt << c.R, c.t;
  const Eigen::Matrix<double, 3, 4> P = K * Rt;
  cv::Matx34d m;
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 4; ++col) m(r, col) = P(r, col);
  return m;
}

}  // namespace

TEST_CASE("differential: 8-point F is as good as cv::findFundamentalMat(FM_8POINT)", "[opencv]") {
  const Rig rig = pinhole_rig();
  std::mt19937_64 rng(21);
  for (int trial = 0; trial < 20; ++trial) {
    const int count = 20 + 30 * trial;
    std::vector<Vec2> x0, x1;
    for (const Vec3& X : visible_points(rig, count, rng)) {
      x0.push_back(measure(rig.cam0.project(X), 0.3, true, rng));
      x1.push_back(measure(rig.cam1.project(X), 0.3, true, rng));
    }
    const Result<Eigen::Matrix3d> ours = fundamental_8point(x0, x1);
    REQUIRE(ours.ok());
    const cv::Mat cvF = cv::findFundamentalMat(to_cv(x0), to_cv(x1), cv::FM_8POINT);
    REQUIRE(cvF.rows == 3);
    Eigen::Matrix3d theirs;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) theirs(r, c) = cvF.at<double>(r, c);
    const double d_ours = mean_epipolar_distance(*ours, x0, x1);
    const double d_theirs = mean_epipolar_distance(theirs, x0, x1);
    INFO("trial " << trial << ", " << count << " points: ours " << d_ours << " px, OpenCV " << d_theirs << " px");
    CHECK(d_ours <= 1.01 * d_theirs);
    CHECK(d_ours < 0.6);
  }
}

TEST_CASE("differential: optimal triangulation is as good as cv::correctMatches + triangulatePoints",
          "[opencv]") {
  const Rig rig = pinhole_rig();
  std::mt19937_64 rng(22);
  const std::vector<Vec3> truth = visible_points(rig, 2000, rng);
  std::vector<Vec2> x0, x1;
  for (const Vec3& X : truth) {
    x0.push_back(measure(rig.cam0.project(X), 0.3, true, rng));
    x1.push_back(measure(rig.cam1.project(X), 0.3, true, rng));
  }
  // The same F for both: from the true cameras.
  const Eigen::Matrix3d K0 = camera_matrix(rig.cam0.K), K1 = camera_matrix(rig.cam1.K);
  const Vec3& t = rig.cam1.t;
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d F = K1.inverse().transpose() * tx * rig.cam1.R * K0.inverse();
  cv::Matx33d cvF;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) cvF(r, c) = F(r, c);

  cv::Mat p0(1, static_cast<int>(x0.size()), CV_64FC2), p1(1, static_cast<int>(x1.size()), CV_64FC2);
  for (size_t i = 0; i < x0.size(); ++i) {
    p0.at<cv::Vec2d>(0, static_cast<int>(i)) = {x0[i].x(), x0[i].y()};
    p1.at<cv::Vec2d>(0, static_cast<int>(i)) = {x1[i].x(), x1[i].y()};
  }
  cv::Mat c0, c1, X4;
  cv::correctMatches(cv::Mat(cvF), p0, p1, c0, c1);
  cv::triangulatePoints(projection(rig.cam0), projection(rig.cam1), c0.reshape(1, static_cast<int>(x0.size())).t(),
                        c1.reshape(1, static_cast<int>(x1.size())).t(), X4);
  REQUIRE(X4.cols == static_cast<int>(truth.size()));

  double ours_sq = 0, theirs_sq = 0;
  int accepted = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const Triangulation tr = triangulate(rig.cam0, rig.cam1, x0[i], x1[i], TriangulationMethod::Optimal);
    accepted += tr.accepted;
    ours_sq += (tr.X - truth[i]).squaredNorm();
    const int col = static_cast<int>(i);
    const Vec3 cvX = Vec3(X4.at<double>(0, col), X4.at<double>(1, col), X4.at<double>(2, col)) / X4.at<double>(3, col);
    theirs_sq += (cvX - truth[i]).squaredNorm();
  }
  const double ours = std::sqrt(ours_sq / static_cast<double>(truth.size()));
  const double theirs = std::sqrt(theirs_sq / static_cast<double>(truth.size()));
  INFO("3D RMS: ours " << ours * 1000 << " mm, OpenCV " << theirs * 1000 << " mm");
  CHECK(ours <= 1.01 * theirs);
  CHECK(ours < 1e-3);
  CHECK(accepted == static_cast<int>(truth.size()));
}
