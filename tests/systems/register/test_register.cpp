// The registration system: marks touched with a resting pen, a registration from them, pen samples mapped
// into the object's frame, rejections in words, touches not drawn, and its state through a snapshot.
#include <catch2/catch.hpp>
#include <Eigen/Geometry>

#include "systems/register/register.hpp"

using namespace fire;

namespace {

// The object's pose in the rig: object = A rig + b.
const Eigen::Matrix3d kA = Eigen::AngleAxisd(0.7, Vec3(0.2, 1, 0.3).normalized()).toRotationMatrix();
const Vec3 kB(0.05, -0.12, 0.4);
Vec3 to_rig(const Vec3& object) { return kA.transpose() * (object - kB); }

// One frame of the system with a tracked pen: what it passes on to the sketch system.
std::vector<InputEvent> run(RegistrationState& s, std::vector<Rejection>& rejections, const std::vector<InputEvent>& frame) {
  std::vector<InputEvent> out;
  register_system(frame, {}, true, s, out, rejections);
  return out;
}

InputEvent pen(int64_t t_us, const Vec3& p) {
  InputEvent e;
  e.t_us = t_us;
  e.kind = EventKind::Pen;
  e.p = p;
  return e;
}
InputEvent event(int64_t t_us, EventKind kind) {
  InputEvent e;
  e.t_us = t_us;
  e.kind = kind;
  return e;
}
InputEvent mark(int64_t t_us, uint32_t n, const Vec3& object, uint32_t line) {
  InputEvent e = event(t_us, EventKind::Command);
  e.command = CommandKind::Mark;
  e.mark = n;
  e.p = object;
  e.line = line;
  return e;
}
InputEvent register_command(int64_t t_us, uint32_t line) {
  InputEvent e = event(t_us, EventKind::Command);
  e.command = CommandKind::Register;
  e.line = line;
  return e;
}

// The pen rests 0.8 s at `rig_point` (a touch: down, samples 10 ms apart, up), then `command` is logged, one
// frame per event; returns the frames' output events.
std::vector<InputEvent> rest(RegistrationState& s, std::vector<Rejection>& rejections, int64_t& t, const Vec3& rig_point,
                             InputEvent command, double wobble = 0) {
  std::vector<InputEvent> out;
  auto frame = [&](InputEvent e) {
    const std::vector<InputEvent> passed = run(s, rejections, {std::move(e)});
    out.insert(out.end(), passed.begin(), passed.end());
  };
  frame(event(t, EventKind::Down));
  for (int k = 0; k < 80; ++k, t += 10'000) frame(pen(t, rig_point + Vec3(k % 2 ? wobble : -wobble, 0, 0)));
  command.t_us = t;
  frame(std::move(command));
  frame(event(t, EventKind::Up));
  t += 500'000;
  return out;
}

// The pen rests on mark n at `object` and `cmd mark n X Y Z` is logged.
std::vector<InputEvent> touch(RegistrationState& s, std::vector<Rejection>& rejections, int64_t& t, uint32_t n,
                              const Vec3& object, uint32_t line, double wobble = 0) {
  return rest(s, rejections, t, to_rig(object), mark(t, n, object, line), wobble);
}

const Vec3 kMarks[] = {{0.03, 0, 0.01}, {-0.03, 0.01, 0.05}, {0, -0.03, 0.12}, {0.01, 0.02, 0.18}};

}  // namespace

TEST_CASE("a registration on three or more marks maps later pen samples into the object's frame") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  for (uint32_t n = 0; n < 4; ++n) CHECK(touch(s, rejections, t, n, kMarks[n], 10 + n).empty());  // touches are not drawn
  CHECK(s.touched.size() == 4);
  std::vector<InputEvent> frame = run(s, rejections, {register_command(t, 20)});
  CHECK(frame.empty());
  CHECK(rejections.empty());
  REQUIRE(s.transform);
  REQUIRE(s.done.size() == 1);
  CHECK(s.done[0].marks == 4);
  CHECK(s.done[0].residual < 1e-9);
  CHECK(s.touched.empty());
  CHECK(s.touches_dropped == 4);

  // A stroke: held back while within the touch radius of its start, then released whole, in the object's frame.
  frame = run(s, rejections, {event(t, EventKind::Down), pen(t + 1, to_rig(Vec3(0.02, 0, 0.05)))});
  CHECK(frame.empty());
  frame = run(s, rejections, {pen(t + 2, to_rig(Vec3(0.02, 0, 0.051)))});
  CHECK(frame.empty());
  frame = run(s, rejections, {pen(t + 3, to_rig(Vec3(0.02, 0, 0.06))), event(t + 4, EventKind::Up)});
  REQUIRE(frame.size() == 5);
  CHECK(frame[0].kind == EventKind::Down);
  CHECK(frame[4].kind == EventKind::Up);
  CHECK((frame[1].p - Vec3(0.02, 0, 0.05)).norm() < 1e-12);
  CHECK((frame[3].p - Vec3(0.02, 0, 0.06)).norm() < 1e-12);
  CHECK(rejections.empty());
}

TEST_CASE("a registration with fewer than 3 marks is rejected in words and keeps the marks touched") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  touch(s, rejections, t, 0, kMarks[0], 10);
  touch(s, rejections, t, 1, kMarks[1], 11);
  CHECK(run(s, rejections, {register_command(t, 12)}).empty());
  REQUIRE(rejections.size() == 1);
  CHECK(rejections[0].line == 12);
  CHECK(rejections[0].reason.find("register: 2 mark(s) touched since the last registration, a registration needs at least 3") == 0);
  CHECK(!s.transform);
  CHECK(s.touched.size() == 2);
  // A third mark and the registration goes through.
  touch(s, rejections, t, 2, kMarks[2], 13);
  run(s, rejections, {register_command(t, 14)});
  CHECK(rejections.size() == 1);
  CHECK(s.transform);
}

TEST_CASE("marks on a line, a moving pen, a wrong mark and an unseen pen are rejected") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  touch(s, rejections, t, 0, Vec3(0, 0, 0), 1);
  touch(s, rejections, t, 1, Vec3(0, 0, 0.1), 2);
  touch(s, rejections, t, 2, Vec3(0, 0, 0.2), 3);
  run(s, rejections, {register_command(t, 4)});
  REQUIRE(rejections.size() == 1);
  CHECK(rejections[0].reason.find("collinear") != std::string::npos);

  touch(s, rejections, t, 3, kMarks[0], 5, 0.004);  // wobbling 4 mm
  REQUIRE(rejections.size() == 2);
  CHECK(rejections[1].reason.find("mark 3: the pen's samples spread 4.00 mm (rms)") == 0);
  CHECK(rejections[1].reason.find("(at most 2.00 mm); hold it still") != std::string::npos);

  run(s, rejections, {mark(t + 2'000'000, 4, kMarks[1], 6)});  // no pen sample for 2 s
  REQUIRE(rejections.size() == 3);
  CHECK(rejections[2].reason.find("mark 4: the pen was seen 0 time(s)") == 0);

  // Mark 2 logged with coordinates 3 cm off: the marks no longer fit a rigid motion.
  RegistrationState w;
  std::vector<Rejection> wrong;
  t = 0;
  touch(w, wrong, t, 0, kMarks[0], 1);
  touch(w, wrong, t, 1, kMarks[1], 2);
  touch(w, wrong, t, 2, kMarks[2], 3);
  w.touched.back().model += Vec3(0.03, 0, 0);
  touch(w, wrong, t, 3, kMarks[3], 4);
  run(w, wrong, {register_command(t, 5)});
  REQUIRE(wrong.size() == 1);
  CHECK(wrong[0].reason.find("register: the marks do not fit one rigid motion") == 0);
  // The other three fit, so the rejection names the odd one, and touching it again mends the registration.
  INFO(wrong[0].reason);
  CHECK(wrong[0].reason.find("mark 2 fits worst, 30.00 mm from where the other 3 put it; touch it again") != std::string::npos);
  CHECK(!w.transform);
  touch(w, wrong, t, 2, kMarks[2], 6);
  run(w, wrong, {register_command(t, 7)});
  CHECK(wrong.size() == 1);
  REQUIRE(w.transform);
  CHECK(w.done.back().marks == 4);
}

TEST_CASE("a mark touched before the object turned is named when the next registration does not fit") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  // Mark 0 touched, the registration rejected (one mark); the object turns, and marks 1, 2, 3 are touched in
  // the new pose. Mark 0's touch still counts, from the old pose.
  touch(s, rejections, t, 0, kMarks[0], 1);
  run(s, rejections, {register_command(t, 2)});
  REQUIRE(rejections.size() == 1);
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.5, Vec3::UnitY()).toRotationMatrix();
  auto touch_turned = [&](uint32_t n, uint32_t line) {
    std::vector<InputEvent> frames{event(t, EventKind::Down)};
    for (int k = 0; k < 80; ++k, t += 10'000) frames.push_back(pen(t, turn * to_rig(kMarks[n])));
    frames.push_back(mark(t, n, kMarks[n], line));
    frames.push_back(event(t, EventKind::Up));
    run(s, rejections, frames);
    t += 500'000;
  };
  for (uint32_t n = 1; n < 4; ++n) touch_turned(n, 10 + n);
  run(s, rejections, {register_command(t, 20)});
  REQUIRE(rejections.size() == 2);
  CHECK(rejections[1].reason.find("register: the marks do not fit one rigid motion") == 0);
  CHECK(rejections[1].reason.find("mark 0 fits worst, ") != std::string::npos);
  CHECK(rejections[1].reason.find("touched before the object moved") != std::string::npos);
  CHECK(!s.transform);
  touch_turned(0, 21);
  run(s, rejections, {register_command(t, 22)});
  CHECK(rejections.size() == 2);
  REQUIRE(s.transform);
  const Vec3 p(0.01, 0.01, 0.1);
  CHECK((s.transform->R * (turn * to_rig(p)) + s.transform->t - p).norm() < 1e-9);
}

TEST_CASE("a second registration replaces the transform") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  for (uint32_t n = 0; n < 3; ++n) touch(s, rejections, t, n, kMarks[n], n);
  run(s, rejections, {register_command(t, 9)});
  // The object turned: the same marks now sit elsewhere in the rig; touched (with the new pose) and registered.
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(2.0, Vec3::UnitY()).toRotationMatrix();
  for (uint32_t n = 0; n < 4; ++n) {
    // Touch at the turned position: the rig sees to_rig(object) turned about the rig's y axis.
    std::vector<InputEvent> frames{event(t, EventKind::Down)};
    for (int k = 0; k < 80; ++k, t += 10'000) frames.push_back(pen(t, turn * to_rig(kMarks[n])));
    frames.push_back(mark(t, n, kMarks[n], 20 + n));
    frames.push_back(event(t, EventKind::Up));
    CHECK(run(s, rejections, frames).empty());
    t += 500'000;
  }
  run(s, rejections, {register_command(t, 30)});
  CHECK(rejections.empty());
  REQUIRE(s.done.size() == 2);
  const Vec3 p(0.01, 0.01, 0.1);
  CHECK((s.transform->R * (turn * to_rig(p)) + s.transform->t - p).norm() < 1e-9);
}

TEST_CASE("the registration state survives a snapshot") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  for (uint32_t n = 0; n < 3; ++n) touch(s, rejections, t, n, kMarks[n], n);
  run(s, rejections, {register_command(t, 9)});
  touch(s, rejections, t, 3, kMarks[3], 10);
  CHECK(run(s, rejections, {event(t, EventKind::Down), pen(t, to_rig(kMarks[0]))}).empty());  // a stroke held back

  SnapshotWriter out;
  s.save(out);
  const std::string file = out.finish();
  Result<SnapshotReader> in = SnapshotReader::open(file, "test");
  REQUIRE(in.ok());
  RegistrationState back;
  REQUIRE(back.load(*in));
  CHECK(in->at_end());
  REQUIRE(back.transform);
  CHECK(back.transform->R == s.transform->R);
  CHECK(back.transform->t == s.transform->t);
  CHECK(back.touched.size() == 1);
  CHECK(back.touched[0].measured == s.touched[0].measured);
  CHECK(back.recent == s.recent);
  CHECK(back.held.size() == 2);
  CHECK(back.stroke_open);
  CHECK(back.done.size() == 1);
  CHECK(back.touches_dropped == s.touches_dropped);
}

TEST_CASE("without a tracked pen the events pass unchanged and mark and register are rejected") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  InputEvent hid = event(0, EventKind::Hid);
  std::vector<InputEvent> out;
  register_system({event(0, EventKind::Down), pen(1, Vec3(1, 2, 3)), event(2, EventKind::Up), hid, mark(3, 0, kMarks[0], 7),
                   register_command(4, 8)},
                  {}, false, s, out, rejections);
  REQUIRE(out.size() == 3);  // the device report is the triangulation system's
  CHECK(out[1].p == Vec3(1, 2, 3));
  REQUIRE(rejections.size() == 2);
  CHECK(rejections[0].reason == "mark: registration needs a tracked pen (a log of device reports, replayed with --rig)");
  CHECK(rejections[1].line == 8);
}

TEST_CASE("a resting pen whose depth flickers between two levels touches the mark at their mean, and its stroke is dropped") {
  // As tracked on the mug's seed 2, far from both cameras: the pen still, its depth stepping 3.5 mm and back,
  // more than the touch radius, so part of the touch went to the sketch system before the mark was touched.
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  const Vec3 rest = to_rig(kMarks[0]);
  std::vector<InputEvent> passed;
  auto frame = [&](std::vector<InputEvent> events) {
    const std::vector<InputEvent> out = run(s, rejections, std::move(events));
    passed.insert(passed.end(), out.begin(), out.end());
  };
  frame({event(t, EventKind::Down)});
  for (int k = 0; k < 80; ++k, t += 10'000) frame({pen(t, rest + Vec3(0, 0, (k / 10) % 2 ? 0.00175 : -0.00175))});
  REQUIRE(passed.size() > 2);
  CHECK(passed.front().kind == EventKind::Down);
  const size_t released = passed.size();
  frame({mark(t, 0, kMarks[0], 1)});
  // The mark is passed on, so the sketch system drops what it was given; the rest of the touch is not passed.
  REQUIRE(passed.size() == released + 1);
  CHECK(passed.back().kind == EventKind::Command);
  CHECK(passed.back().command == CommandKind::Mark);
  for (int k = 0; k < 20; ++k, t += 10'000) frame({pen(t, rest + Vec3(0, 0, k % 2 ? 0.004 : -0.004))});
  frame({event(t, EventKind::Up)});
  CHECK(passed.size() == released + 1);
  CHECK(s.touches_dropped == 1);
  CHECK(rejections.empty());
  REQUIRE(s.touched.size() == 1);
  CHECK((s.touched[0].measured - rest).norm() < 5e-4);  // between the levels, nearer the one shown longer

  // The next stroke is drawn as before, from its own Down.
  t += 500'000;
  frame({event(t, EventKind::Down), pen(t + 1, rest), pen(t + 2, rest + Vec3(0.01, 0, 0)), event(t + 3, EventKind::Up)});
  REQUIRE(passed.size() == released + 5);
  CHECK(passed[released + 1].kind == EventKind::Down);
  CHECK(passed.back().kind == EventKind::Up);

  // Sliding 1 cm across the mark in the same half second: its samples spread 2.8 mm (rms), refused.
  t += 500'000;
  frame({event(t, EventKind::Down)});
  for (int k = 0; k < 80; ++k, t += 10'000) frame({pen(t, rest + Vec3(0.0002 * k, 0, 0))});
  frame({mark(t, 1, kMarks[1], 2), event(t, EventKind::Up)});
  REQUIRE(rejections.size() == 1);
  CHECK(rejections[0].reason.find("mark 1: the pen's samples spread 2.") == 0);
  CHECK(s.touched.size() == 1);
}

namespace {

// Marks measured by touch: the command with no coordinates (cmd table, cmd measure N, cmd mark N).
InputEvent touch_command(CommandKind kind, uint32_t n, uint32_t line) {
  InputEvent e = event(0, EventKind::Command);
  e.command = kind;
  e.mark = n;
  e.line = line;
  return e;
}

// The table the object stands on: its z = 0, in the object's frame, touched around it.
const Vec3 kTable[] = {{0.1, 0, 0}, {-0.05, 0.08, 0}, {-0.05, -0.08, 0}};

// The object stood at `pose` (object = A rig + b): the pen rests at `object`, then `kind` is logged.
void rest_at(RegistrationState& s, std::vector<Rejection>& rejections, int64_t& t, const Vec3& object, CommandKind kind,
             uint32_t n, uint32_t line, const Eigen::Matrix3d& A = kA, const Vec3& b = kB) {
  rest(s, rejections, t, A.transpose() * (object - b), touch_command(kind, n, line));
}

// Three table touches and marks 0..3 measured, then registered: the object's frame made.
void measure_all(RegistrationState& s, std::vector<Rejection>& rejections, int64_t& t) {
  for (uint32_t k = 0; k < 3; ++k) rest_at(s, rejections, t, kTable[k], CommandKind::Table, 0, 1 + k);
  for (uint32_t n = 0; n < 4; ++n) rest_at(s, rejections, t, kMarks[n], CommandKind::Measure, n, 10 + n);
  run(s, rejections, {register_command(t, 20)});
}

}  // namespace

TEST_CASE("marks measured by touch make the object's frame: +z the table's normal, the origin under the marks, +x camera 0's x") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  for (uint32_t k = 0; k < 3; ++k) rest_at(s, rejections, t, kTable[k], CommandKind::Table, 0, 1 + k);
  for (uint32_t n = 0; n < 4; ++n) rest_at(s, rejections, t, kMarks[n], CommandKind::Measure, n, 10 + n);
  CHECK(s.table.size() == 3);
  REQUIRE(s.measured.size() == 4);
  CHECK(!s.transform);  // the marks wait, in the rig's frame, for the registration
  CHECK((s.measured[2].p - to_rig(kMarks[2])).norm() < 1e-12);
  CHECK(s.touches_dropped == 7);  // no touch is drawn
  run(s, rejections, {register_command(t, 20)});
  CHECK(rejections.empty());
  REQUIRE(s.transform);
  REQUIRE(s.done.size() == 1);
  CHECK(s.done[0].measured_frame);
  CHECK(s.done[0].marks == 4);
  const tracking::RigidTransform T = *s.transform;
  CHECK((T.R * T.R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  CHECK(T.R.determinant() > 0);
  // Heights above the table and distances between marks are the object's; the centroid stands on the origin.
  Vec3 centroid = Vec3::Zero();
  for (uint32_t n = 0; n < 4; ++n) {
    CHECK(s.measured[n].mark == n);
    CHECK(s.measured[n].line == 10 + n);
    CHECK(std::abs(s.measured[n].p.z() - kMarks[n].z()) < 1e-9);
    CHECK(std::abs((s.measured[n].p - s.measured[0].p).norm() - (kMarks[n] - kMarks[0]).norm()) < 1e-9);
    centroid += s.measured[n].p / 4;
  }
  CHECK(std::abs(centroid.x()) < 1e-12);
  CHECK(std::abs(centroid.y()) < 1e-12);
  for (const Vec3& p : kTable) CHECK(std::abs((T.R * to_rig(p) + T.t).z()) < 1e-9);
  // +x: camera 0's x axis laid on the table.
  const Vec3 up = T.R.row(2).transpose(), x = Vec3::UnitX() - up.x() * up;
  CHECK((T.R.row(0).transpose() - x.normalized()).norm() < 1e-12);
  CHECK(up.dot(Vec3::Zero() - to_rig(Vec3::Zero())) > 0);  // toward the camera

  // The object turned: registered on three measured marks (cmd mark N), the same point of it maps to the same place.
  const Eigen::Matrix3d A2 = Eigen::AngleAxisd(-1.1, Vec3(0.1, 0.3, 1).normalized()).toRotationMatrix();
  const Vec3 b2(-0.02, 0.05, 0.45);
  for (uint32_t n : {1u, 2u, 3u}) rest_at(s, rejections, t, kMarks[n], CommandKind::MarkMeasured, n, 30 + n, A2, b2);
  run(s, rejections, {register_command(t, 40)});
  CHECK(rejections.empty());
  REQUIRE(s.done.size() == 2);
  CHECK(!s.done[1].measured_frame);
  CHECK(s.done[1].residual < 1e-9);
  const Vec3 before = T.R * to_rig(Vec3(0.02, 0.01, 0.07)) + T.t;
  const Vec3 after = s.transform->R * (A2.transpose() * (Vec3(0.02, 0.01, 0.07) - b2)) + s.transform->t;
  CHECK((after - before).norm() < 1e-9);
  // A mark measured after the turn is placed in the same frame.
  rest_at(s, rejections, t, Vec3(0.04, -0.02, 0.09), CommandKind::Measure, 7, 41, A2, b2);
  REQUIRE(s.measured.size() == 5);
  CHECK((s.measured[4].p - (T.R * to_rig(Vec3(0.04, -0.02, 0.09)) + T.t)).norm() < 1e-9);
  const std::vector<std::string> said = describe_registration(s);
  REQUIRE(said.size() >= 3);
  CHECK(said[0].find("registration 1 (line 20): the object's frame from the table") == 0);
  CHECK(said[2] == "5 mark(s) measured: 0, 1, 2, 3, 7");
}

TEST_CASE("a mark measured twice, marks too close or on a line, a table on a line and too few table touches are rejected") {
  std::vector<Rejection> rejections;
  int64_t t = 0;
  {
    RegistrationState s;
    rest_at(s, rejections, t, kTable[0], CommandKind::Table, 0, 1);
    rest_at(s, rejections, t, kTable[1], CommandKind::Table, 0, 2);
    rest_at(s, rejections, t, kTable[0] + Vec3(0.004, 0, 0), CommandKind::Table, 0, 3);  // the same point again
    REQUIRE(rejections.size() == 1);
    CHECK(rejections[0].reason.find("table: the pen rests 4.00 mm from table touch 1") == 0);
    for (uint32_t n = 0; n < 3; ++n) rest_at(s, rejections, t, kMarks[n], CommandKind::Measure, n, 10 + n);
    rest_at(s, rejections, t, kMarks[1], CommandKind::Measure, 1, 14);  // the same number again
    REQUIRE(rejections.size() == 2);
    CHECK(rejections[1].line == 14);
    CHECK(rejections[1].reason.find("measure mark 1: measured already (line 11)") == 0);
    rest_at(s, rejections, t, kMarks[2] + Vec3(0, 0.006, 0), CommandKind::Measure, 5, 15);  // the same mark, a new number
    REQUIRE(rejections.size() == 3);
    CHECK(rejections[2].reason.find("measure mark 5: the pen rests 6.00 mm from mark 2") == 0);
    CHECK(rejections[2].reason.find("the same mark touched twice?") != std::string::npos);
    CHECK(s.measured.size() == 3);
    run(s, rejections, {register_command(t, 16)});
    REQUIRE(rejections.size() == 4);
    CHECK(rejections[3].reason.find("register: the object's frame needs 3 touches on the table around the object (cmd table), 2 made") == 0);
    CHECK(!s.transform);
    // A third table touch, but on the line of the first two.
    rest_at(s, rejections, t, 0.5 * (kTable[0] + kTable[1]) + Vec3(0, 0.002, 0), CommandKind::Table, 0, 17);
    run(s, rejections, {register_command(t, 18)});
    REQUIRE(rejections.size() == 5);
    CHECK(rejections[4].reason.find("register: the table touches lie on a line") == 0);
    CHECK(rejections[4].reason.find("; the touches are kept") != std::string::npos);
    CHECK(s.table.size() == 3);
    CHECK(!s.transform);
  }
  {
    RegistrationState s;
    rejections.clear();
    for (uint32_t k = 0; k < 3; ++k) rest_at(s, rejections, t, kTable[k], CommandKind::Table, 0, 1 + k);
    for (uint32_t n = 0; n < 3; ++n) rest_at(s, rejections, t, Vec3(0.01, 0, 0.03 + 0.04 * n), CommandKind::Measure, n, 10 + n);
    run(s, rejections, {register_command(t, 20)});
    REQUIRE(rejections.size() == 1);
    CHECK(rejections[0].reason.find("register: the measured marks lie on a line") == 0);
    CHECK(!s.transform);
    rest_at(s, rejections, t, kMarks[1], CommandKind::Measure, 3, 21);  // off the line: the frame is made
    run(s, rejections, {register_command(t, 22)});
    CHECK(rejections.size() == 1);
    CHECK(s.transform);
    rest_at(s, rejections, t, kTable[0], CommandKind::Table, 0, 23);
    REQUIRE(rejections.size() == 2);
    CHECK(rejections[1].reason.find("table: the object's frame is made already (registration at line 22)") == 0);
  }
}

TEST_CASE("a mark never measured, too few measured marks after a turn and a measured mark that fits badly are named") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  rest_at(s, rejections, t, kMarks[0], CommandKind::MarkMeasured, 0, 5);
  REQUIRE(rejections.size() == 1);
  CHECK(rejections[0].reason.find("mark 0: not measured (no mark is); measure it first (cmd measure N)") == 0);
  measure_all(s, rejections, t);
  REQUIRE(rejections.size() == 1);
  REQUIRE(s.transform);
  const tracking::RigidTransform first = *s.transform;

  const Eigen::Matrix3d A2 = Eigen::AngleAxisd(2.0, Vec3(0.3, 0.2, 1).normalized()).toRotationMatrix();
  const Vec3 b2(0.01, -0.03, 0.42);
  rest_at(s, rejections, t, kMarks[0], CommandKind::MarkMeasured, 9, 30, A2, b2);
  REQUIRE(rejections.size() == 2);
  CHECK(rejections[1].reason.find("mark 9: not measured (marks 0, 1, 2, 3 are)") == 0);
  // After the turn only two measured marks face the cameras.
  for (uint32_t n : {0u, 1u}) rest_at(s, rejections, t, kMarks[n], CommandKind::MarkMeasured, n, 31 + n, A2, b2);
  run(s, rejections, {register_command(t, 33)});
  REQUIRE(rejections.size() == 3);
  CHECK(rejections[2].reason.find("register: 2 mark(s) touched since the last registration, a registration needs at least 3: "
                                  "touch 3 of the marks measured (0, 1, 2, 3) that both cameras see") == 0);
  CHECK(rejections[2].reason.find("measure marks (cmd measure N) on the side that will face them") != std::string::npos);
  CHECK(s.transform->t == first.t);  // the frame is kept
  // Two more, mark 3 touched 4 cm from where it was measured: the registration names it.
  rest_at(s, rejections, t, kMarks[2], CommandKind::MarkMeasured, 2, 34, A2, b2);
  rest_at(s, rejections, t, kMarks[3] + Vec3(0.04, 0, 0), CommandKind::MarkMeasured, 3, 35, A2, b2);
  run(s, rejections, {register_command(t, 36)});
  REQUIRE(rejections.size() == 4);
  CHECK(rejections[3].reason.find("mark 3 fits worst, 40.00 mm from where the other 3 put it") != std::string::npos);
  CHECK(s.done.size() == 1);
  rest_at(s, rejections, t, kMarks[3], CommandKind::MarkMeasured, 3, 37, A2, b2);  // touched again: it registers
  run(s, rejections, {register_command(t, 38)});
  CHECK(rejections.size() == 4);
  CHECK(s.done.size() == 2);
}

TEST_CASE("measured marks and table touches survive a snapshot, and a snapshot written before them still loads") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  measure_all(s, rejections, t);
  rest_at(s, rejections, t, Vec3(0.04, -0.02, 0.09), CommandKind::Measure, 7, 41);
  REQUIRE(s.measured.size() == 5);
  SnapshotWriter out;
  s.save(out);
  const std::string file = out.finish();
  Result<SnapshotReader> in = SnapshotReader::open(file, "test");
  REQUIRE(in.ok());
  RegistrationState back;
  REQUIRE(back.load(*in));
  CHECK(in->at_end());
  CHECK(back.table == s.table);
  REQUIRE(back.measured.size() == 5);
  CHECK(back.measured[4].mark == 7);
  CHECK(back.measured[4].p == s.measured[4].p);
  CHECK(back.measured[4].line == 41);
  REQUIRE(back.done.size() == 1);
  CHECK(back.done[0].measured_frame);
  REQUIRE(back.rounds.size() == 1);
  CHECK(back.rounds[0].size() == 5);
  CHECK(back.rounds[0][4].rest == s.rounds[0][4].rest);
  REQUIRE(back.frame_transform);
  CHECK(back.frame_transform->R == s.frame_transform->R);

  // A snapshot written before marks were measured: the same state without them, less the record that holds
  // them, which is then its record byte, three empty counts (table, marks, rounds), a flag per registration
  // and the frame's flag.
  RegistrationState before = s;
  before.table.clear();
  before.measured.clear();
  before.rounds.clear();
  before.frame_transform.reset();
  SnapshotWriter without;
  before.save(without);
  const size_t trailer = 1 + 3 * 8 + before.done.size() + 1;
  const std::string payload = without.finish().substr(kSnapshotHeaderBytes);
  SnapshotWriter old;
  for (size_t k = 0; k + trailer < payload.size(); ++k) old.put(uint8_t(payload[k]));
  const std::string old_file = old.finish();
  Result<SnapshotReader> old_in = SnapshotReader::open(old_file, "old");
  REQUIRE(old_in.ok());
  RegistrationState old_back;
  REQUIRE(old_back.load(*old_in));
  CHECK(old_in->at_end());
  CHECK(old_back.transform->t == s.transform->t);
  CHECK(old_back.measured.empty());
  CHECK(old_back.table.empty());
  CHECK(!old_back.done[0].measured_frame);
}

TEST_CASE("a mark measured through a registration with a bad touch is mended by the next registration that touches it") {
  RegistrationState s;
  std::vector<Rejection> rejections;
  int64_t t = 0;
  measure_all(s, rejections, t);  // marks 0-3 exactly, in the first pose
  REQUIRE(s.transform);
  // The measured frame is the object's moved rigidly: that motion, from the exact first round.
  std::vector<Vec3> object_points, measured_points;
  for (uint32_t n = 0; n < 4; ++n) {
    object_points.push_back(kMarks[n]);
    measured_points.push_back(s.measured[n].p);
  }
  const Result<tracking::RigidTransform> M = tracking::register_rigid(object_points, measured_points);
  REQUIRE(M.ok());
  const Vec3 mark4(0.035, 0.03, 0.15);
  auto error_of_mark4 = [&] { return (s.measured_mark(4)->p - (M->R * mark4 + M->t)).norm(); };

  // Turned: registered on 0, 1 and 2, mark 2 touched 1 mm off; then mark 4 measured, which inherits the tilt.
  const Eigen::Matrix3d A2 = Eigen::AngleAxisd(0.9, Vec3(0.1, 0.2, 1).normalized()).toRotationMatrix();
  const Vec3 b2(0.02, -0.04, 0.43);
  rest_at(s, rejections, t, kMarks[0], CommandKind::MarkMeasured, 0, 30, A2, b2);
  rest_at(s, rejections, t, kMarks[1], CommandKind::MarkMeasured, 1, 31, A2, b2);
  rest_at(s, rejections, t, kMarks[2] + Vec3(0.001, 0, 0), CommandKind::MarkMeasured, 2, 32, A2, b2);
  run(s, rejections, {register_command(t, 33)});
  rest_at(s, rejections, t, mark4, CommandKind::Measure, 4, 34, A2, b2);
  REQUIRE(s.measured_mark(4));
  const double before = error_of_mark4();
  CHECK(before > 5e-4);

  // Turned again: every mark touched exactly. The rounds refit together put mark 4 nearer where it is.
  const Eigen::Matrix3d A3 = Eigen::AngleAxisd(-0.6, Vec3(0.2, 0.1, 1).normalized()).toRotationMatrix();
  const Vec3 b3(-0.03, 0.02, 0.41);
  for (uint32_t n = 0; n < 4; ++n) rest_at(s, rejections, t, kMarks[n], CommandKind::MarkMeasured, n, 40 + n, A3, b3);
  rest_at(s, rejections, t, mark4, CommandKind::MarkMeasured, 4, 44, A3, b3);
  run(s, rejections, {register_command(t, 45)});
  CHECK(rejections.empty());
  REQUIRE(s.rounds.size() == 3);
  CHECK(s.rounds[1].size() == 4);  // the three touched and mark 4 measured
  CHECK(error_of_mark4() < 0.5 * before);
  // The latest motion maps a point of the object where the first round's frame has it.
  const Vec3 point(0.01, -0.02, 0.1);
  CHECK((s.transform->R * (A3.transpose() * (point - b3)) + s.transform->t - (M->R * point + M->t)).norm() < 2e-4);
}
