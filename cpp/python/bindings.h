// Shared helpers of the binding translation units.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <span>

template <typename T>
using carray = pybind11::array_t<T, pybind11::array::c_style | pybind11::array::forcecast>;

template <typename T>
std::span<const T> cspan(const carray<T>& a)
{
  return std::span<const T>(a.data(), a.size());
}

void declare_contact(pybind11::module_& m);
void declare_rigid(pybind11::module_& m);
void declare_junction(pybind11::module_& m);
