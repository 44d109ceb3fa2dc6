#pragma once
// rig.json: the calibrated stereo rig, see README.md in this folder for the format.
#include <string>
#include <string_view>

#include "engine/common.hpp"
#include "systems/tracking/calibration.hpp"

namespace fire::tracking {

// {"format":"fire-rig","version":1,...}; doubles written with 17 significant digits so a
// round trip is exact.
std::string rig_to_json(const CalibrationResult& rig);
// `source` names the input in error messages (usually the file path).
Result<CalibrationResult> rig_from_json(std::string_view text, const std::string& source);

}  // namespace fire::tracking
