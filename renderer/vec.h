// Small 3-vector templated on the scalar (float or double), as pbrt's Vector3.
// Everything is constexpr-friendly and header-only: the kernels inline it.
#pragma once
#include <algorithm>
#include <cmath>
#include <ostream>

namespace ra {

template <class T>
struct Vec3 {
  T x{}, y{}, z{};
  constexpr Vec3() = default;
  constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
  template <class U>
  constexpr explicit Vec3(const Vec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

  constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3& operator+=(const Vec3& o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  constexpr Vec3& operator-=(const Vec3& o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  constexpr Vec3& operator*=(T s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  constexpr bool operator==(const Vec3& o) const = default;
};

template <class T>
constexpr Vec3<T> operator*(T s, const Vec3<T>& v) {
  return v * s;
}
template <class T>
constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
constexpr Vec3<T> mul(const Vec3<T>& a, const Vec3<T>& b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <class T>
T length(const Vec3<T>& v) {
  return std::sqrt(dot(v, v));
}
template <class T>
Vec3<T> normalize(const Vec3<T>& v) {
  return v / length(v);
}
template <class T>
Vec3<T> abs(const Vec3<T>& v) {
  return {std::abs(v.x), std::abs(v.y), std::abs(v.z)};
}
template <class T>
Vec3<T> vmin(const Vec3<T>& a, const Vec3<T>& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <class T>
Vec3<T> vmax(const Vec3<T>& a, const Vec3<T>& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <class T>
T max_component(const Vec3<T>& v) {
  return std::max(v.x, std::max(v.y, v.z));
}
template <class T>
int max_dimension(const Vec3<T>& v) {
  return (v.x > v.y) ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2);
}
template <class T>
std::ostream& operator<<(std::ostream& os, const Vec3<T>& v) {
  return os << '(' << v.x << ", " << v.y << ", " << v.z << ')';
}

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

// x rounded to float and back, through a volatile float: GCC 12.2 (Debian
// 12's g++ 12.2.0) at -O2 and -O3 compiles a vectorised pair of
// double(float(x)) to x unchanged, silently skipping the rounding. Use this
// wherever a double must hold exactly what a float computation would see.
inline double to_float32(double x) {
  volatile float f = float(x);
  return f;
}
inline Vec3<double> to_float32(const Vec3<double>& v) { return {to_float32(v.x), to_float32(v.y), to_float32(v.z)}; }

}  // namespace ra
