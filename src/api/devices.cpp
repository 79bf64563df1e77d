#include "gpu/context.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist {

Result<std::vector<DeviceInfo>> listDevices() { return gpu::describeDevices(); }

}  // namespace rthdist
