#include "tools/app/app_live.hpp"

#include <algorithm>
#include <cstdio>

#include "platform/files.hpp"
#include "platform/wiimote/hidapi_backend.hpp"
#include "platform/wiimote/roles.hpp"
#include "engine/ir_report.hpp"
#include "tools/app/session_rig.hpp"

namespace fire::app {

namespace {

std::string millimetres(const Vec3& p) {
  char text[64];
  std::snprintf(text, sizeof text, "(%.0f, %.0f, %.0f) mm", p.x() * 1e3, p.y() * 1e3, p.z() * 1e3);
  return text;
}

}  // namespace

Result<std::unique_ptr<AppLive>> AppLive::open(const AppLiveOptions& o) {
  using R = Result<std::unique_ptr<AppLive>>;
  std::unique_ptr<AppLive> app(new AppLive(o));
  std::string rig_json, marks_json;
  wiimote::Backend* backend = nullptr;
  wiimote::Clock clock;
  std::string rig_source = o.rig_path;
  if (o.fake_rig_seed) {
    auto fake = FakeDrawingRig::create(*o.fake_rig_seed, o.fake_strokes, o.fake_measure_marks);
    if (!fake) return R::failure(fake.error());
    app->fake_ = std::move(*fake);
    rig_json = app->fake_->rig_json();
    marks_json = app->fake_->marks_json();
    rig_source = "the fake rig's rig.json";
    backend = &app->fake_->remotes().backend();
    clock = app->fake_->remotes().clock();
  } else {
    auto text = read_text_file(o.rig_path);
    if (!text) return R::failure("--rig: " + text.error());
    rig_json = std::move(*text);
    if (!o.marks_path.empty()) {
      auto marks = read_text_file(o.marks_path);
      if (!marks) return R::failure("--marks: " + marks.error());
      marks_json = std::move(*marks);
    }
    app->hardware_ = std::make_unique<wiimote::HidapiBackend>();
    backend = app->hardware_.get();
    clock = wiimote::system_clock();
  }
  auto assigned = wiimote::remotes_from_rig_json(rig_json, rig_source);
  if (!assigned) return R::failure(assigned.error());
  if (!marks_json.empty()) {
    auto marks = marks_from_json(marks_json, o.fake_rig_seed ? "the fake rig's marks" : o.marks_path);
    if (!marks) return R::failure(marks.error());
    app->marks_ = std::move(*marks);
  }
  World& w = app->world_;
  w.surface_options = o.surface;
  auto rig = tracking_rig_from_json(rig_json, rig_source, InputLog{}, o.session_dir);
  if (!rig) return R::failure(rig.error());
  set_rig(w, *rig);

  app->log_ = std::make_unique<wiimote::LogWriter>(clock);
  wiimote::DriverOptions driver_options;
  driver_options.startup.sensitivity = o.ir_sensitivity;
  app->driver_ = std::make_unique<wiimote::Driver>(*backend, *app->log_, *assigned, driver_options, clock);
  auto scan = app->driver_->open_all();
  if (!scan) return R::failure(scan.error());
  const int cameras = app->driver_->cameras();
  if (cameras < 2) {
    std::string why = "--live needs the rig's two camera remotes and found " + std::to_string(cameras);
    for (const std::string& e : scan->open_errors) why += "\n  " + e;
    return R::failure(why + "\n  (fire devices --rig " + (o.rig_path.empty() ? std::string("RIG") : o.rig_path) +
                      " lists what this machine sees)");
  }
  // The folder is made once the cameras are there, so a failed start leaves none behind.
  auto out = SessionWriter::create(o.session_dir, settings_json(w), rig_json, marks_json);
  if (!out) return R::failure(out.error());
  app->out_.emplace(std::move(*out));
  app->live_.emplace(w, app->scheduler_, *app->log_, *app->out_, o.write);
  app->live_->on_taken([self = app.get()](std::span<const InputEvent> taken) { self->observe(taken); });
  if (!app->fake_) app->driver_->start();  // the fake rig's remotes are read on the frame loop's thread
  return app;
}

AppLive::~AppLive() {
  if (driver_) driver_->stop();
}

void AppLive::observe(std::span<const InputEvent> taken) {
  const int pad = wiimote::log_device(wiimote::Role::CommandPad);
  for (const InputEvent& e : taken) {
    if (e.kind == EventKind::Meta && e.name == "device_lost" && e.text.rfind(std::to_string(pad) + " ", 0) == 0)
      pad_.forget();
    if (e.kind != EventKind::Hid) continue;
    if (e.device == pad) {
      for (PadAction a : pad_.on_report(e.bytes)) pad_actions_.push_back(a);
      continue;
    }
    if (e.device < 0 || e.device > 1) continue;
    const DecodedReport d = decode_ir_report(e.bytes);
    if (d.status != ReportStatus::Ok) continue;
    window::CameraView& view = cameras_[size_t(e.device)];
    view.present = true;
    view.blobs.clear();
    for (const IrSlot& s : d.report.slots)
      if (s.seen) view.blobs.push_back({float(s.x), float(s.y), int(s.size)});
    view.pen_seen = !view.blobs.empty();
  }
}

std::vector<std::string> AppLive::step() {
  if (fake_) {
    // A displayed frame is a 60th of a second of the drawing, times the speed.
    const auto ns = int64_t(1e9 / 60 * options_.fake_speed);
    fake_->remotes().advance(ns, *driver_, [this] { live_->step(); });
  } else {
    live_->step();
  }
  measured_in_view_.clear();
  for (const MeasuredMark& m : world_.registration.measured) measured_in_view_.push_back(m.p);
  std::vector<std::string> messages;
  std::vector<PadAction> actions;
  actions.swap(pad_actions_);
  for (PadAction a : actions) messages.push_back("pad: " + act(a));
  for (const wiimote::Notice& n : driver_->take_notices())
    messages.push_back(wiimote::describe(n));
  return messages;
}

void AppLive::command(CommandKind kind, const Vec3& p) {
  InputEvent e;
  e.kind = EventKind::Command;
  e.command = kind;
  e.p = p;
  log_->command(std::move(e));
}

std::string AppLive::act(PadAction action) {
  switch (action) {
    case PadAction::CloseBorder: command(CommandKind::Close); return "closing the border";
    case PadAction::Undo: command(CommandKind::Undo); return "undo";
    case PadAction::Redo: command(CommandKind::Redo); return "redo";
    case PadAction::DeleteLastCurve:
    case PadAction::SharpLastCurve: {
      const bool remove = action == PadAction::DeleteLastCurve;
      const std::optional<Vec3> p = last_curve_point(world_.history);
      if (!p) return std::string("no curve drawn to ") + (remove ? "delete" : "mark sharp");
      command(remove ? CommandKind::Delete : CommandKind::Sharp, *p);
      return remove ? "deleting the curve drawn last" : "the curve drawn last: sharp / smooth";
    }
    case PadAction::HoleLastTouched:
      // The pen is lit only while it touches: where it last touched is where the person pointed.
      command(CommandKind::Hole, world_.pen_feedback.pen);
      return "a hole at the face the pen last touched";
    case PadAction::TouchTable:
      if (!marks_.empty()) return "the table is touched only to measure marks, and the marks file gives them";
      command(CommandKind::Table);
      return "the table touched (" + std::to_string(world_.registration.table.size() + 1) + " of " + std::to_string(kTableTouches) + ")";
    case PadAction::TouchMark: {
      if (marks_.empty()) {
        // No marks file: the mark shown is measured, or once measured (and the object has a frame) touched.
        const RegistrationState& r = world_.registration;
        const uint32_t mark = uint32_t(shown_mark_);
        const bool measured = r.transform && r.measured_mark(mark);
        InputEvent e;
        e.kind = EventKind::Command;
        e.command = measured ? CommandKind::MarkMeasured : CommandKind::Measure;
        e.mark = mark;
        log_->command(std::move(e));
        shown_mark_ = (shown_mark_ + 1) % kMeasuredMarkIds;
        return "mark " + std::to_string(mark) + (measured ? " touched" : " measured");
      }
      InputEvent e;
      e.kind = EventKind::Command;
      e.command = CommandKind::Mark;
      e.mark = uint32_t(shown_mark_);
      e.p = marks_[shown_mark_];
      log_->command(std::move(e));
      // The register system takes the command next frame; until then the world counts the marks before it.
      const std::vector<MarkTouch>& touched = world_.registration.touched;
      const bool again = std::any_of(touched.begin(), touched.end(),
                                     [&](const MarkTouch& t) { return t.mark == shown_mark_; });
      const std::string done = "mark " + std::to_string(shown_mark_) + " touched (" +
                               std::to_string(touched.size() + (again ? 0 : 1)) + " since the last registration)";
      shown_mark_ = (shown_mark_ + 1) % marks_.size();
      return done;
    }
    case PadAction::Register: {
      command(CommandKind::Register);
      return "registering on " + std::to_string(world_.registration.touched.size()) + " mark(s)";
    }
    case PadAction::PreviousMark:
    case PadAction::NextMark: {
      const size_t ids = marks_.empty() ? kMeasuredMarkIds : marks_.size();
      shown_mark_ = (shown_mark_ + (action == PadAction::NextMark ? 1 : ids - 1)) % ids;
      return "touch mark " + std::to_string(shown_mark_) + " next";
    }
  }
  return {};
}

void AppLive::fill_hud(window::HudData& hud) const {
  hud.live.clear();
  for (const wiimote::RemoteView& v : driver_->remotes()) hud.live.push_back(wiimote::describe(v));
  if (!marks_.empty()) {
    hud.live.push_back("next mark: " + std::to_string(shown_mark_) + " of " + std::to_string(marks_.size()) + " at " +
                       millimetres(marks_[shown_mark_]));
    hud.live.push_back("rest the pen on it, press 2 (or M); Home (or R) registers");
  } else {
    const RegistrationState& r = world_.registration;
    std::string ids;
    for (const MeasuredMark& m : r.measured) ids += (ids.empty() ? "" : ", ") + std::to_string(m.mark);
    hud.live.push_back("marks measured by touch: " + (ids.empty() ? std::string("none yet") : ids));
    if (!r.transform) {
      hud.live.push_back("table: " + std::to_string(r.table.size()) + " of " + std::to_string(kTableTouches) +
                         " touches (rest the pen on it around the object, press up or T)");
      hud.live.push_back("mark " + std::to_string(shown_mark_) + ": rest the pen on it, press 2 (or M) to measure; " +
                         "Home (or R) makes the object's frame");
    } else if (r.measured_mark(uint32_t(shown_mark_))) {
      hud.live.push_back("mark " + std::to_string(shown_mark_) + ", measured: press 2 (or M) on it to register on it; Home (or R) registers");
    } else {
      hud.live.push_back("mark " + std::to_string(shown_mark_) + ", new: rest the pen on it, press 2 (or M) to measure it");
    }
  }
  hud.cameras = cameras_;
}

const std::vector<Vec3>& AppLive::marks_in_view() const {
  static const std::vector<Vec3> none;
  if (!world_.registration.transform) return none;
  return marks_.empty() ? measured_in_view_ : marks_;
}

size_t AppLive::shown_mark() const {
  if (!marks_.empty()) return shown_mark_;
  const std::vector<MeasuredMark>& measured = world_.registration.measured;
  for (size_t k = 0; k < measured.size(); ++k)
    if (measured[k].mark == shown_mark_) return k;
  return measured.size();  // not measured yet: none highlighted
}

Status AppLive::finish() {
  if (stopped_) return Status::success();
  stopped_ = true;
  driver_->stop();
  if (fake_) fake_->remotes().advance(8'000'000, *driver_, [] {});  // what the fake remotes still hold
  return live_->finish();
}

}  // namespace fire::app
