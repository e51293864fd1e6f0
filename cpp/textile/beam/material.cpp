#include "material.h"

#include <cmath>
#include <stdexcept>

namespace textile::beam
{
void validate(const Material& m)
{
  if (!std::isfinite(m.young) or m.young <= 0)
    throw std::invalid_argument("Material: young modulus must be positive and finite");
  if (!std::isfinite(m.poisson) or m.poisson <= -1.0 or m.poisson >= 0.5)
    throw std::invalid_argument("Material: poisson ratio must lie in (-1, 0.5)");
}
} // namespace textile::beam
