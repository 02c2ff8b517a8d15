#include <vfield/volume/volume_detail.h>

#include "fine_grid.h"

#include <vfield/core/field_visitors.h>

namespace vfield {

void DetailSettings::validate() const { checkFields(*this); }

double DetailSettings::displacementRange() const
{
    double octaveSum = 0.0, weight = 1.0;
    for (int octave = 0; octave < octaves; ++octave, weight *= gain) octaveSum += weight;
    return amplitude * octaveSum / frequency;
}

void CondensationSettings::validate() const { checkFields(*this); }

float CondensationSettings::share(float y, float peak, float origin) const
{
    if (!enabled()) return 1.0f;
    const double level = lift > 0.0 ? double(origin) + lift : double(peak);
    return float(smoothstep01(1.0 - (level - double(y)) / depth));
}

} // namespace vfield
