// A ray with a parametric window [tmin, tmax]: a hit counts only when
// tmin <= t <= tmax, so shadow rays and secondary rays need no special cases.
#pragma once
#include <limits>

#include "vec.h"

namespace ra {

template <class T>
struct Ray {
  Vec3<T> o;  // origin
  Vec3<T> d;  // direction, not necessarily unit length
  T tmin = T(0);
  T tmax = std::numeric_limits<T>::infinity();

  constexpr Vec3<T> at(T t) const { return o + d * t; }
  template <class U>
  constexpr explicit operator Ray<U>() const {
    return {Vec3<U>(o), Vec3<U>(d), U(tmin), U(tmax)};
  }
};

using Rayf = Ray<float>;
using Rayd = Ray<double>;

}  // namespace ra
