#include "platform/wiimote/hidapi_backend.hpp"

#include <hidapi.h>

#include <cerrno>
#include <cstring>

#include "platform/wiimote/setup_advice.hpp"

namespace fire::wiimote {
namespace {

// hidapi reports strings as wchar_t; addresses and messages are ASCII in practice.
std::string narrow(const wchar_t* w) {
  std::string out;
  if (!w) return out;
  for (; *w; ++w) out += (*w >= 0x20 && *w < 0x7F) ? static_cast<char>(*w) : '?';
  return out;
}

// Large enough for any Wii Remote input report.
constexpr size_t kReadBuffer = 64;

class HidapiDevice : public Device {
 public:
  HidapiDevice(hid_device* handle, std::string path) : handle_(handle), path_(std::move(path)) {}
  ~HidapiDevice() override { hid_close(handle_); }
  HidapiDevice(const HidapiDevice&) = delete;
  HidapiDevice& operator=(const HidapiDevice&) = delete;

  Status write(std::span<const uint8_t> report) override {
    if (hid_write(handle_, report.data(), report.size()) < 0)
      return Status::failure(path_ + ": write failed: " + narrow(hid_error(handle_)));
    return Status::success();
  }

  ReadResult read(int timeout_ms) override {
    uint8_t buf[kReadBuffer];
    const int n = hid_read_timeout(handle_, buf, sizeof buf, timeout_ms);
    if (n < 0) return {.status = ReadStatus::Gone, .report = {}, .error = path_ + ": " + narrow(hid_error(handle_))};
    if (n == 0) return {};
    return {.status = ReadStatus::Report, .report = Bytes(buf, buf + n), .error = {}};
  }

 private:
  hid_device* handle_;
  std::string path_;
};

}  // namespace

HidapiBackend::HidapiBackend() { initialised_ = hid_init() == 0; }

HidapiBackend::~HidapiBackend() {
  if (initialised_) hid_exit();
}

Result<std::vector<DeviceInfo>> HidapiBackend::enumerate() {
  using R = Result<std::vector<DeviceInfo>>;
  if (!initialised_) return R::failure("hidapi could not be initialised");
  std::vector<DeviceInfo> out;
  hid_device_info* list = hid_enumerate(kNintendoVendor, 0);
  for (hid_device_info* d = list; d; d = d->next)
    out.push_back({.vendor = d->vendor_id, .product = d->product_id, .serial = narrow(d->serial_number),
                   .path = d->path ? d->path : "", .product_name = narrow(d->product_string)});
  hid_free_enumeration(list);
  return out;
}

Result<std::unique_ptr<Device>> HidapiBackend::open(const DeviceInfo& info) {
  using R = Result<std::unique_ptr<Device>>;
  const std::string name = info.path + " (" + normalize_address(info.serial) + ")";
  if (!initialised_) return R::failure(name + ": hidapi could not be initialised");
  if (permission_denied(info.path)) return R::failure(name + ": " + permission_advice(info.path));
  if (const auto binding = kernel_binding(info.path); binding && binding->driver == kKernelWiimoteDriver)
    return R::failure(name + ": " + unbind_advice(*binding));
  hid_device* handle = hid_open_path(info.path.c_str());
  if (!handle) {
    const int err = errno;
    std::string why = narrow(hid_error(nullptr));
    if (why.empty()) why = std::strerror(err);
    return R::failure(name + ": cannot open: " + why);
  }
  return R(std::make_unique<HidapiDevice>(handle, name));
}

}  // namespace fire::wiimote
