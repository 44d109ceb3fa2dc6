#pragma once
// What `fire aim` shows of the camera remotes while a person aims them (aim_run.hpp runs it): per camera,
// the blobs of its last IR report with their sizes, where the pen has been seen, the IR reports over the last
// second, battery and sensitivity; the problems a person aiming them must hear of, each a sentence naming the
// camera; with a rig, where the working volume lies in each image and which part of it the other camera sees;
// and each camera's picture. It reads no clock and no device: reports come in with their stamps (the driver's
// arrival instants), so the same reports give the same state and the same words.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine/camera.hpp"
#include "engine/ir_report.hpp"
#include "platform/render/image.hpp"

namespace fire::app {

// A camera reporting fewer IR reports than this over a second is named (a Wii Remote sends 100).
inline constexpr double kAimMinRateHz = 80;
// The rate's window, and how long one camera may see the pen while the other does not before it is named.
inline constexpr int64_t kAimWindowUs = 1'000'000;
// A light one camera sees, and the other does not, that stays this long within kAimStillPx of where it came to
// rest is a stray: the pen would be seen by both, and rests for a moment only. Below kAimWindowUs, so that a
// stray is named as one before it could be taken for the pen seen by one camera alone.
inline constexpr int64_t kAimStrayStillUs = 500'000;
// A light both cameras see that stays still this long is a lamp or a reflection too (or the pen held still):
// the simulated person rests the pen on a mark for a second.
inline constexpr int64_t kAimLampStillUs = 3'000'000;
inline constexpr double kAimStillPx = 5;
// The trail of the pen's blobs, and the working volume, are kept in square cells of these many sensor pixels.
inline constexpr int kAimTrailCellPx = 4;
inline constexpr int kAimVolumeCellPx = 8;
inline constexpr int kAimTrailColumns = kWiimoteWidth / kAimTrailCellPx, kAimTrailRows = kWiimoteHeight / kAimTrailCellPx;
inline constexpr int kAimVolumeColumns = kWiimoteWidth / kAimVolumeCellPx;
inline constexpr int kAimVolumeRows = kWiimoteHeight / kAimVolumeCellPx;

struct AimBlob {
  uint16_t x = 0, y = 0;  // sensor pixels, as reported: x right in 0..1023, y down in 0..767
  uint8_t size = 0;       // 0..15
  bool stray = false;     // a still light taken for a stray, not the pen
};

struct AimCamera {
  bool reporting = false;  // an IR report has come
  int rate_hz = 0;         // IR reports in the second before now
  std::optional<int> battery_percent;
  bool battery_low = false;
  int sensitivity = 0;
  std::vector<AimBlob> blobs;   // its last IR report's; none once it has been silent for a while
  std::vector<AimBlob> strays;  // every stray light named so far, where it was last seen
  std::vector<uint32_t> trail;  // kAimTrailColumns x kAimTrailRows cells, row by row: the pen's blobs seen there
};

enum class AimProblemKind : uint8_t { StrayLight, PenSeenByOne, LowRate, LowBattery };
struct AimProblem {
  AimProblemKind kind = AimProblemKind::StrayLight;
  int camera = 0;  // the camera that sees the stray or the pen alone, is slow, or whose battery is low
  std::string text;
};

class AimMonitor {
 public:
  // `sensitivity`: the level the driver set the cameras up with (1 to 5, 6 the high-sensitivity block).
  explicit AimMonitor(int sensitivity);

  // An IR report of camera 0 or 1, stamped `t_us` on the driver's clock (a camera's stamps never decrease).
  void report(int camera, int64_t t_us, const IrSlots& slots);
  // What the camera's last status report says of its battery.
  void battery(int camera, int percent, bool low);
  // The rates over the second before `now_us` (same clock) and the problems now; call before reading them.
  void advance(int64_t now_us);

  const AimCamera& camera(int c) const { return cameras_[size_t(c)].view; }
  // The problems now, by camera.
  const std::vector<AimProblem>& problems() const { return problems_; }
  // Each problem (a kind and a camera) the first time it was named, in that order.
  const std::vector<AimProblem>& named() const { return named_; }

 private:
  // One light followed from report to report: where it is and where it came to rest.
  struct Track {
    double x = 0, y = 0;
    double rest_x = 0, rest_y = 0;
    int64_t still_since_us = 0, last_us = 0;
    uint8_t size = 0;
    bool stray = false;
    bool both = false;  // the other camera sees a light that came to rest with it: a stray only as a lamp
  };
  struct Camera {
    AimCamera view;
    std::vector<Track> tracks;
    std::vector<int64_t> stamps;  // of the IR reports in the rate's window
    int64_t first_us = -1, last_us = -1;
    bool pen_seen = false;  // its last report shows a light that is not a stray
    std::optional<int64_t> alone_since_us;  // it sees the pen and the other camera does not, since then
  };

  void follow(Camera& c, int64_t t_us, const IrSlots& slots);
  void classify(Camera& c, const Camera& other, int64_t t_us);
  static bool sees_pen(const Camera& c, int64_t t_us);

  std::array<Camera, 2> cameras_;
  std::vector<AimProblem> problems_, named_;
};

// The working volume: a box 40 cm across, 30 cm high and 40 cm deep (the wand's of `fire simulate wand`)
// around the point where the two cameras' axes pass closest, its first axis along the baseline.
struct WorkingVolume {
  Vec3 centre = Vec3::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns: across, up, deep
  Vec3 half = Vec3(0.2, 0.15, 0.2);
};
WorkingVolume working_volume(const tracking::Camera& cam0, const tracking::Camera& cam1);

// Where the working volume lies in one camera's image, per kAimVolumeCellPx cell.
enum class VolumeCell : uint8_t { Outside, ThisCameraOnly, BothCameras };
// Per camera, kAimVolumeColumns x kAimVolumeRows cells row by row: whether the ray through a cell's centre
// crosses the volume, and whether the other camera sees a point of the volume on it.
std::array<std::vector<VolumeCell>, 2> volume_cells(const tracking::Camera& cam0, const tracking::Camera& cam1);
// The share of a camera's image where both cameras see the working volume.
double overlap_share(std::span<const VolumeCell> cells);

// The pictures' colours (RGB).
struct AimColour {
  static constexpr uint8_t background[3] = {14, 16, 24};
  static constexpr uint8_t both[3] = {16, 64, 58};        // the working volume, seen by both cameras
  static constexpr uint8_t this_only[3] = {72, 30, 28};   // the working volume, seen by this camera only
  static constexpr uint8_t trail[3] = {110, 160, 255};    // where the pen's blobs have been
  static constexpr uint8_t pen[3] = {255, 255, 255};      // the last report's blobs
  static constexpr uint8_t stray[3] = {255, 140, 0};      // stray lights
};
// A blob's radius in sensor pixels: it grows with the blob's size.
inline double aim_blob_radius_px(uint8_t size) { return 6.0 + 2.0 * size; }

// One camera's picture at half the sensor's size (512 x 384): the working volume's cells (none: no rig), the
// pen's trail, every stray light named, and the last report's blobs as discs (strays in their colour).
render::Image aim_picture(const AimCamera& camera, std::span<const VolumeCell> volume);

}  // namespace fire::app
