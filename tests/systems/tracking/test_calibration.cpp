// Wand calibration on synthetic rigs: exact recovery, convergence from wrong nominal
// intrinsics under the device's noise, the progress observer, and clear errors on unusable
// input; rig.json round trip.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <catch2/catch.hpp>
#include "synthetic.hpp"
#include "systems/tracking/calibration.hpp"
#include "systems/tracking/rig_io.hpp"
#include "systems/tracking/triangulation.hpp"

using namespace fire;
using namespace fire::tracking;
using namespace fire::tracking::test;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Intrinsics scaled_focal(Intrinsics K, double factor) {
  K.fx *= factor;
  K.fy *= factor;
  K.k1 = 0;
  return K;
}

Rig distorted_rig() { return accuracy_rig(true_intrinsics(0), true_intrinsics(1)); }

}  // namespace

TEST_CASE("calibration: noise-free wand data is recovered exactly", "[calibration]") {
  const Rig rig = distorted_rig();
  std::mt19937_64 rng(11);
  const auto obs = wand_observations(rig, 300, 0.3, 0.0, false, rng);
  CalibrationOptions o{scaled_focal(true_intrinsics(0), 1.02), scaled_focal(true_intrinsics(1), 0.98), 0.3, 100};
  const Result<CalibrationResult> r = calibrate_wand(obs, o);
  REQUIRE(r.ok());
  CHECK(r->observations_used == 300);
  CHECK(r->reprojection_rms_px < 1e-9);
  CHECK(r->wand_length_error_mm < 1e-6);
  const Intrinsics* K[2] = {&r->cam0.K, &r->cam1.K};
  for (int c = 0; c < 2; ++c) {
    const Intrinsics T = true_intrinsics(c);
    CHECK(std::abs(K[c]->fx - T.fx) < 1e-6);
    CHECK(std::abs(K[c]->fy - T.fy) < 1e-6);
    CHECK(std::abs(K[c]->cx - T.cx) < 1e-6);
    CHECK(std::abs(K[c]->cy - T.cy) < 1e-6);
    CHECK(std::abs(K[c]->k1 - T.k1) < 1e-9);
  }
  CHECK((r->cam1.R - rig.cam1.R).norm() < 1e-9);
  CHECK((r->cam1.t - rig.cam1.t).norm() < 1e-9);
  CHECK(r->cam0.R == Eigen::Matrix3d::Identity());
  CHECK(r->cam0.t == Vec3::Zero());
}

TEST_CASE("calibration: converges from a 2 % wrong focal length with 0.3 px noise and integer pixels",
          "[calibration]") {
  const Rig rig = distorted_rig();
  std::mt19937_64 rng(12);
  const auto obs = wand_observations(rig, 1500, 0.3, 0.3, true, rng);
  for (double factor : {0.98, 1.02}) {
    CalibrationOptions o{scaled_focal(wiimote_nominal_intrinsics(), factor * 1342.0 / 1330.0),
                         scaled_focal(wiimote_nominal_intrinsics(), factor * 1321.0 / 1330.0), 0.3, 100};
    const Result<CalibrationResult> r = calibrate_wand(obs, o);
    REQUIRE(r.ok());
    INFO("focal factor " << factor << ": rms " << r->reprojection_rms_px << " px, wand "
                         << r->wand_length_error_mm << " mm, " << r->iterations << " iterations");
    // Per coordinate; the noise is sqrt(0.3^2 + 1/12) = 0.42 px, of which the 5 wand parameters
    // per frame absorb 5 of 8 residual dimensions: expected sqrt(3/8) * 0.42 = 0.25 px.
    CHECK(r->reprojection_rms_px < 0.28);
    CHECK(r->reprojection_rms_px > 0.22);
    CHECK(r->reprojection_rms_2d_px == Approx(std::sqrt(2.0) * r->reprojection_rms_px));
    CHECK(r->wand_length_error_mm < 1.0);
    CHECK(r->observations_used >= 1490);
    for (int c = 0; c < 2; ++c) {
      const Intrinsics T = true_intrinsics(c);
      const Intrinsics& K = c == 0 ? r->cam0.K : r->cam1.K;
      CHECK(std::abs(K.fx / T.fx - 1) < 0.003);
      CHECK(std::abs(K.fy / T.fy - 1) < 0.003);
      CHECK(std::abs(K.cx - T.cx) < 3.0);
      CHECK(std::abs(K.cy - T.cy) < 3.0);
      CHECK(std::abs(K.k1 - T.k1) < 0.01);
    }
    CHECK(rotation_angle_deg(r->cam1.R, rig.cam1.R) < 0.05);
    CHECK((r->cam1.t - rig.cam1.t).norm() < 0.002);

    // Static points triangulated with the calibrated rig land within a millimetre.
    std::mt19937_64 point_rng(13);
    double sum = 0;
    const auto points = visible_points(rig, 400, point_rng);
    for (const Vec3& X : points) {
      const Triangulation t = triangulate(r->cam0, r->cam1, measure(rig.cam0.project(X), 0.3, true, point_rng),
                                          measure(rig.cam1.project(X), 0.3, true, point_rng),
                                          TriangulationMethod::Optimal);
      sum += (t.X - X).squaredNorm();
    }
    CHECK(std::sqrt(sum / static_cast<double>(points.size())) < 1e-3);
  }
}

TEST_CASE("calibration: frames with a wrong blob are rejected, the rest still calibrate", "[calibration]") {
  const Rig rig = distorted_rig();
  std::mt19937_64 rng(15);
  auto obs = wand_observations(rig, 1000, 0.3, 0.3, true, rng);
  // 5 % of the frames get a stray reflection in place of one LED, somewhere in the image.
  std::uniform_real_distribution<double> x(0, 1023), y(0, 767);
  int corrupted = 0;
  for (size_t i = 0; i < obs.size(); i += 20) {
    (i % 40 == 0 ? obs[i].cam0 : obs[i].cam1)[i % 3 == 0 ? 0 : 1] = Vec2(std::round(x(rng)), std::round(y(rng)));
    ++corrupted;
  }
  CalibrationOptions o{wiimote_nominal_intrinsics(), wiimote_nominal_intrinsics(), 0.3, 100};
  const Result<CalibrationResult> r = calibrate_wand(obs, o);
  REQUIRE(r.ok());
  INFO("rms " << r->reprojection_rms_px << " px, used " << r->observations_used);
  CHECK(r->observations_rejected >= corrupted);
  CHECK(r->observations_used >= 1000 - corrupted - 20);
  CHECK(r->reprojection_rms_px < 0.28);
  CHECK(std::abs(r->cam0.K.fx / true_intrinsics(0).fx - 1) < 0.003);
  CHECK((r->cam1.t - rig.cam1.t).norm() < 0.002);
}

TEST_CASE("calibration: the progress observer shows the adjustment converge and changes nothing",
          "[calibration]") {
  const Rig rig = distorted_rig();
  std::mt19937_64 rng(16);
  auto obs = wand_observations(rig, 800, 0.3, 0.3, true, rng);
  // A few blobs off by 5 px: too little for the epipolar test to catch, so that the adjustment
  // also resumes without outliers.
  for (size_t i = 0; i < obs.size(); i += 40) obs[i].cam1[0] += Vec2(5, 0);
  CalibrationOptions o{scaled_focal(wiimote_nominal_intrinsics(), 1.02), wiimote_nominal_intrinsics(), 0.3, 100};
  const Result<CalibrationResult> plain = calibrate_wand(obs, o);
  REQUIRE(plain.ok());

  std::vector<CalibrationProgress> seen;
  o.on_iteration = [&seen](const CalibrationProgress& p) { seen.push_back(p); };
  const Result<CalibrationResult> observed = calibrate_wand(obs, o);
  REQUIRE(observed.ok());
  // rig.json writes each double as the shortest decimal that reads back to its bits.
  CHECK(rig_to_json(*observed) == rig_to_json(*plain));

  REQUIRE(seen.size() >= 3);
  CHECK(seen.front().iteration == 0);
  CHECK_FALSE(seen.front().finished);
  CHECK(seen.front().frames > observed->observations_used);  // some outliers were dropped on the way
  const CalibrationProgress& last = seen.back();
  CHECK(last.finished);
  CHECK(last.iteration == observed->iterations);
  CHECK(last.frames == observed->observations_used);
  CHECK(last.reprojection_rms_px == observed->reprojection_rms_px);  // the same expression on the same cost
  for (size_t i = 0; i < seen.size(); ++i) {
    const CalibrationProgress& p = seen[i];
    INFO("report " << i << ": iteration " << p.iteration << ", rms " << p.reprojection_rms_px << " px");
    CHECK(std::isfinite(p.reprojection_rms_px));
    CHECK(std::isfinite(p.camera_rms_px[0]));
    CHECK(std::isfinite(p.camera_rms_px[1]));
    // The combined figure is the root of the mean of the cameras' squares (each has 4 of the 8 coordinates).
    const double mean_square =
        0.5 * (p.camera_rms_px[0] * p.camera_rms_px[0] + p.camera_rms_px[1] * p.camera_rms_px[1]);
    CHECK(std::sqrt(mean_square) == Approx(p.reprojection_rms_px).epsilon(1e-9));
    CHECK(p.finished == (i + 1 == seen.size()));
    if (i == 0) continue;
    CHECK(p.iteration >= seen[i - 1].iteration);
    CHECK(p.reprojection_rms_px <= seen[i - 1].reprojection_rms_px);
  }
}

TEST_CASE("calibration: unusable input gives a clear error", "[calibration]") {
  const Rig rig = distorted_rig();
  std::mt19937_64 rng(14);
  auto obs = wand_observations(rig, 40, 0.3, 0.3, true, rng);
  CalibrationOptions o{wiimote_nominal_intrinsics(), wiimote_nominal_intrinsics(), 0.3, 50};

  SECTION("zero, negative or NaN wand length") {
    for (double length : {0.0, -0.3, kNaN}) {
      o.wand_length_m = length;
      const auto r = calibrate_wand(obs, o);
      REQUIRE_FALSE(r.ok());
      CHECK(r.error().find("wand length") != std::string::npos);
    }
  }
  SECTION("wand never seen by one camera") {
    for (auto& ob : obs) ob.cam1 = {Vec2(kNaN, kNaN), Vec2(kNaN, kNaN)};
    const auto r = calibrate_wand(obs, o);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().find("never seen by camera 1") != std::string::npos);
  }
  SECTION("fewer than 8 usable observations") {
    for (size_t i = 7; i < obs.size(); ++i) obs[i].cam0[1] = Vec2(kNaN, 5);
    const auto r = calibrate_wand(obs, o);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().find("7 usable observations") != std::string::npos);
  }
  SECTION("no observations") {
    const auto r = calibrate_wand(std::span<const WandObservation>(), o);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().find("never seen") != std::string::npos);
  }
  SECTION("a wand held still: degenerate motion") {
    for (auto& ob : obs) ob = obs.front();
    const auto r = calibrate_wand(obs, o);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().find("degenerate") != std::string::npos);
  }
  SECTION("a wand only translated, never turned: degenerate motion") {
    std::vector<WandObservation> slid;
    const Vec3 d = Vec3(1, 0.2, 0.1).normalized();
    std::uniform_real_distribution<double> u(-0.15, 0.15);
    for (int i = 0; i < 200; ++i) {
      const Vec3 c = rig.cube_centre + Vec3(u(rng), u(rng), u(rng));
      const Vec3 A = c + 0.15 * d, B = c - 0.15 * d;
      slid.push_back({i, {rig.cam0.project(A), rig.cam0.project(B)}, {rig.cam1.project(A), rig.cam1.project(B)}});
    }
    const auto r = calibrate_wand(slid, o);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().find("degenerate") != std::string::npos);
  }
}

TEST_CASE("rig.json: doubles round-trip exactly, malformed files give clear errors", "[rig_io]") {
  CalibrationResult rig;
  rig.cam0 = Camera{true_intrinsics(0), Eigen::Matrix3d::Identity(), Vec3::Zero()};
  const Rig truth = distorted_rig();
  rig.cam1 = truth.cam1;
  rig.cam1.K.k2 = 1.0 / 3.0;
  rig.reprojection_rms_px = 0.1 + 0.2;
  rig.reprojection_rms_2d_px = std::sqrt(2.0) * rig.reprojection_rms_px;
  rig.wand_length_error_mm = 1e-300;
  rig.observations_used = 5999;
  rig.observations_rejected = 3;
  rig.iterations = 17;
  const std::string text = rig_to_json(rig);
  CHECK(text.find("\"format\": \"fire-rig\"") != std::string::npos);
  const Result<CalibrationResult> back = rig_from_json(text, "rig.json");
  REQUIRE(back.ok());
  // Bit-for-bit equality of every double.
  CHECK(std::memcmp(&back->cam0.K, &rig.cam0.K, sizeof(Intrinsics)) == 0);
  CHECK(std::memcmp(&back->cam1.K, &rig.cam1.K, sizeof(Intrinsics)) == 0);
  CHECK(back->cam1.R == rig.cam1.R);
  CHECK(back->cam1.t == rig.cam1.t);
  CHECK(back->reprojection_rms_px == rig.reprojection_rms_px);
  CHECK(back->reprojection_rms_2d_px == rig.reprojection_rms_2d_px);
  CHECK(back->wand_length_error_mm == rig.wand_length_error_mm);
  CHECK(back->observations_used == 5999);
  CHECK(back->observations_rejected == 3);
  CHECK(back->iterations == 17);

  auto error_of = [](const std::string& s) { return rig_from_json(s, "bad.json").error(); };
  CHECK(error_of(text.substr(0, text.size() / 2)) == "bad.json: not valid JSON");
  CHECK(error_of("[1,2]") == "bad.json: expected a JSON object");
  CHECK(error_of(R"({"format":"something","version":1})").find("not a rig file") != std::string::npos);
  std::string v2 = text;
  v2.replace(v2.find("\"version\": 1"), 12, "\"version\": 2");
  CHECK(error_of(v2).find("version 2 is not supported") != std::string::npos);
  std::string no_fx = text;
  no_fx.replace(no_fx.find("\"fx\""), 4, "\"fz\"");
  CHECK(error_of(no_fx) == "bad.json: cameras[0].intrinsics: missing \"fx\"");
  std::string bad_r = text;
  bad_r.replace(bad_r.find("\"R\": [") + 6, 0, "[2,0,0],");
  CHECK(error_of(bad_r).find("cameras[0].R: expected 3 rows") != std::string::npos);
  std::string string_t = text;
  const size_t t_pos = string_t.rfind("\"t\": [");
  string_t.replace(string_t.find('[', t_pos) + 1, 0, "\"x\",");
  CHECK(error_of(string_t).find("cameras[1].t") != std::string::npos);
  CalibrationResult skewed = rig;
  skewed.cam1.R(0, 1) += 0.1;
  CHECK(error_of(rig_to_json(skewed)).find("cameras[1].R: not a rotation matrix") != std::string::npos);
  CalibrationResult nonfinite = rig;
  nonfinite.cam1.K.fx = kNaN;  // written as null
  CHECK(error_of(rig_to_json(nonfinite)).find("cameras[1].intrinsics.fx: not a number") != std::string::npos);
}
