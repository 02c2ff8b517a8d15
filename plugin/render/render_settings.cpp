#include <vfield/render/render_settings.h>

#include <vfield/core/field_visitors.h>

#include <cmath>

namespace vfield {

void CameraSettings::validate() const
{
    checkFields(*this);
    require(follow.has_value() || (position - lookAt).length() > 0, "", "position and lookAt must differ");
}

void SunSettings::validate() const { checkFields(*this); }
void SkySettings::validate() const { checkFields(*this); }
void ImageSettings::validate() const
{
    checkFields(*this);
    require(shutterOpen <= shutterClose, "shutter",
            "the shutter closes (" + numberText(shutterClose) + ") before it opens (" + numberText(shutterOpen) + ")");
}
void ViewSettings::validate() const { checkFields(*this); }
void MediumSettings::validate() const { checkFields(*this); }
void MultipleScatteringSettings::validate() const { checkFields(*this); }
void IntegratorSettings::validate() const { checkFields(*this); }
void RenderSettings::validate() const { checkFields(*this); }

uint64_t RenderSettings::hash() const
{
    ContentHash h;
    hashFields(h, *this);
    return h.value();
}

double MediumSettings::phase(double cosTheta) const
{
    const double forward = henyeyGreenstein(cosTheta, anisotropy);
    return backWeight > 0.0 ? (1.0 - backWeight) * forward + backWeight * henyeyGreenstein(cosTheta, backAnisotropy) : forward;
}

double henyeyGreenstein(double cosTheta, double g)
{
    const double denominator = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * M_PI * denominator * std::sqrt(denominator));
}

} // namespace vfield
