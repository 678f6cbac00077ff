// Mathematical constants, one definition each (C++17 has no <numbers>).
// Each is the double nearest the real value; narrowing to float (e.g.
// float(kPi / 4)) rounds once more.
#pragma once

namespace rastray {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 0.31830988618379067154;  // 1/π (the same double as 1.0 / kPi)

}  // namespace rastray
