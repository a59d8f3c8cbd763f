// Small vector math for the built-in renderer (CPU, double precision: it is the data
// source of the tests, so robustness beats speed).
#pragma once

#include <algorithm>
#include <cmath>

namespace mcd::render {

struct Vec3 {
    double x = 0, y = 0, z = 0;

    Vec3() = default;
    constexpr Vec3(double x, double y, double z) : x(x), y(y), z(z) {}
    explicit constexpr Vec3(double v) : x(v), y(v), z(v) {}

    Vec3 operator+(const Vec3 &o) const { return {x + o.x, y + o.y, z + o.z}; }
    Vec3 operator-(const Vec3 &o) const { return {x - o.x, y - o.y, z - o.z}; }
    Vec3 operator*(const Vec3 &o) const { return {x * o.x, y * o.y, z * o.z}; }
    Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
    Vec3 operator-() const { return {-x, -y, -z}; }
    Vec3 &operator+=(const Vec3 &o) { return *this = *this + o; }
    Vec3 &operator*=(const Vec3 &o) { return *this = *this * o; }
    double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    double MaxComponent() const { return std::max(x, std::max(y, z)); }
    double Luminance() const { return 0.2126 * x + 0.7152 * y + 0.0722 * z; }
    bool IsBlack() const { return x == 0 && y == 0 && z == 0; }
};

inline Vec3 operator*(double s, const Vec3 &v) {
    return v * s;
}
inline double Dot(const Vec3 &a, const Vec3 &b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 Cross(const Vec3 &a, const Vec3 &b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double Length(const Vec3 &v) {
    return std::sqrt(Dot(v, v));
}
inline Vec3 Normalize(const Vec3 &v) {
    return v / Length(v);
}
inline Vec3 Reflect(const Vec3 &d, const Vec3 &n) {
    return d - n * (2 * Dot(d, n));
}

struct Ray {
    Vec3 origin, direction;  // direction is unit length
    Vec3 At(double t) const { return origin + direction * t; }
};

// Orthonormal basis around a unit vector w.
struct Frame {
    Vec3 u, v, w;
    explicit Frame(const Vec3 &n) : w(n) {
        Vec3 a = std::fabs(n.x) > 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
        u = Normalize(Cross(a, w));
        v = Cross(w, u);
    }
    Vec3 ToWorld(const Vec3 &l) const { return u * l.x + v * l.y + w * l.z; }
};

constexpr double kPi = 3.14159265358979323846;

}  // namespace mcd::render
