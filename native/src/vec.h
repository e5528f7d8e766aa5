// Small value types for points and directions. Float for what Embree sees,
// double for lens maths (the lens-system camera traces in double).
#pragma once

#include <cmath>

namespace lc {

template <class T>
struct Vec3 {
    T x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <class U>
    constexpr explicit Vec3(const Vec3<U>& v) : x(T(v.x)), y(T(v.y)), z(T(v.z)) {}

    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }
    constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <class T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T> T length(const Vec3<T>& v) { return std::sqrt(dot(v, v)); }
template <class T> Vec3<T> normalize(const Vec3<T>& v) { return v / length(v); }

struct Point2f {
    float x = 0, y = 0;
};

// An orthonormal camera frame in world space (POV-Ray convention: left-handed,
// +y up; camera x right, y up, z along the view direction).
struct Frame {
    Vec3d origin, right, up, forward;

    Vec3d world_from_camera_point(const Vec3d& p) const { return origin + right * p.x + up * p.y + forward * p.z; }
    Vec3d world_from_camera_vector(const Vec3d& v) const { return right * v.x + up * v.y + forward * v.z; }
};

}  // namespace lc
