// IEEE 754 binary16 (half) to float and back, for layers and outputs in half: every half
// is a float exactly; a float rounds to the nearest half, ties to even, beyond 65504 to
// infinity, NaN to a quiet NaN of the same sign.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace mcd {

inline float HalfToFloat(uint16_t half) {
    uint32_t sign = uint32_t(half & 0x8000u) << 16;
    uint32_t exponent = (half >> 10) & 0x1fu, mantissa = half & 0x3ffu;
    uint32_t bits;
    if (exponent == 0x1f) {
        bits = sign | 0x7f800000u | (mantissa << 13);
    } else if (exponent != 0) {
        bits = sign | ((exponent + 112) << 23) | (mantissa << 13);
    } else {
        // Zero or subnormal: mantissa x 2^-24, exact in float.
        float value = float(mantissa) * 5.9604644775390625e-8f;
        return sign ? -value : value;
    }
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
}

inline uint16_t FloatToHalf(float value) {
    uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    uint16_t sign = uint16_t((bits >> 16) & 0x8000u);
    uint32_t magnitude = bits & 0x7fffffffu;
    if (magnitude > 0x7f800000u) return sign | 0x7e00u;   // NaN
    if (magnitude >= 0x477ff000u) return sign | 0x7c00u;  // 65520 and above: infinity
    if (magnitude < 0x38800000u) {
        // Below the smallest normal half (2^-14): a multiple of 2^-24, rounded to the
        // nearest, ties to even (1024 x 2^-24 is the smallest normal's bit pattern).
        float scaled;
        std::memcpy(&scaled, &magnitude, sizeof scaled);
        return sign | uint16_t(std::nearbyint(scaled * 16777216.f));
    }
    // Normal: rebias the exponent (127 - 15) and round 23 mantissa bits to 10; a carry
    // into the exponent is the right result.
    uint32_t half = (magnitude - 0x38000000u) >> 13;
    uint32_t rest = magnitude & 0x1fffu;
    if (rest > 0x1000u || (rest == 0x1000u && (half & 1u))) ++half;
    return sign | uint16_t(half);
}

}  // namespace mcd
