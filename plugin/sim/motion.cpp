#include <vfield/sim/motion.h>

#include <cmath>
#include <limits>

namespace vfield {

double stepLimit(double speed, double acceleration, double reach)
{
    if (acceleration <= 0.0) return speed > 0.0 ? reach / speed : std::numeric_limits<double>::infinity();
    return 2.0 * reach / (speed + std::sqrt(speed * speed + 4.0 * acceleration * reach));
}

void integrateWithDrag(Vec3d& x, Vec3d& v, const Vec3d& a, double drag, double dt)
{
    // (1 - e^-h) / h for h = drag dt, by its series where the closed form loses precision.
    const double h = drag * dt;
    const double relaxed = h < 1e-5 ? 1.0 - h / 2.0 + h * h / 6.0 : -std::expm1(-h) / h;
    v = v * std::exp(-h) + a * (dt * relaxed);
    x += v * dt;
}

} // namespace vfield
