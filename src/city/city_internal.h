// What the tile stage's files share and no caller needs.
#pragma once

namespace hsr {

/// The stage name the tile stage's errors carry ("hsr: city: ...").
inline constexpr const char* kCityStage = "city";

}  // namespace hsr
