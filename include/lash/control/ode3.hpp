#pragma once
/// @file ode3.hpp
/// Fixed-step Bogacki–Shampine integrator, Simulink's "ode3" (the solver the
/// thesis's continuous simulation used, paper 2 §2.7.2). Third order:
///   k1 = f(t, x)
///   k2 = f(t + h/2,  x + h/2·k1)
///   k3 = f(t + 3h/4, x + 3h/4·k2)
///   x(t + h) = x + h·(2/9·k1 + 1/3·k2 + 4/9·k3)
/// (the embedded 2nd-order error estimate is not needed at a fixed step).
/// `f(t, x, dx)` writes dx/dt into `dx`. ode3_step is noexcept if f is;
/// allocation-free, O(N).
#include <array>
#include <cstddef>

namespace lash {

template <std::size_t N, class F>
void ode3_step(F&& f, double t, std::array<double, N>& x, double h) {
  std::array<double, N> k1{}, k2{}, k3{}, tmp{};
  f(t, x, k1);
  for (std::size_t i = 0; i < N; ++i) tmp[i] = x[i] + 0.5 * h * k1[i];
  f(t + 0.5 * h, tmp, k2);
  for (std::size_t i = 0; i < N; ++i) tmp[i] = x[i] + 0.75 * h * k2[i];
  f(t + 0.75 * h, tmp, k3);
  for (std::size_t i = 0; i < N; ++i) x[i] += h * (2.0 / 9.0 * k1[i] + 1.0 / 3.0 * k2[i] + 4.0 / 9.0 * k3[i]);
}

}  // namespace lash
