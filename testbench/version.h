// The version string `saarcor --version` prints.
#pragma once

namespace saarcor {
inline constexpr const char* kVersion = "0.1.0";
}  // namespace saarcor
