// The one error a kernel may raise for a state it cannot evaluate.
//
// A GeometryError means "this iterate is outside the model's domain": a
// folded element (det F <= 0 or axial stretch <= 0 at a quadrature point),
// a contact particle that cannot be placed, a NaN coordinate. The solver
// rejects such an iterate and cuts the load step; every other exception is
// a programming error and propagates with its traceback. In Python it is
// textile.GeometryError (a RuntimeError).
#pragma once

#include <stdexcept>
#include <string>

namespace textile
{
struct GeometryError : std::runtime_error
{
  explicit GeometryError(const std::string& what) : std::runtime_error(what) {}
};
} // namespace textile
