#include <vfield/render/render_settings.h>

#include <vfield/core/field_visitors.h>
#include <vfield/render/camera_path.h>

#include <algorithm>
#include <cmath>

namespace vfield {

void CameraPathSettings::validate() const
{
    checkFields(*this);
    require(points.size() >= 2, "points", "a path needs at least two points");
    for (std::size_t i = 1; i < points.size(); ++i)
        require(points[i] != points[i - 1], "points/" + std::to_string(i), "the same point as the one before it");
    require(end > start, "end", "the path must end (" + numberText(end) + ") after it starts (" + numberText(start) + ")");
}

void CameraSettings::validate() const
{
    checkFields(*this);
    require(!(follow && path), "path", "a camera follows an object or travels a path, not both");
    require(follow || path || (position - lookAt).length() > 0, "", "position and lookAt must differ");
}

CameraSettings CameraSettings::at(double frame) const
{
    CameraSettings camera = atFrame(*this, frame);
    if (path) {
        const CameraPath travelled(path->points);
        const double distance = std::clamp((frame - path->start) / (path->end - path->start), 0.0, 1.0) * travelled.length();
        camera.position = travelled.point(distance);
        if (path->lookAlong) camera.lookAt = camera.position + travelled.direction(distance);
        camera.path.reset();
    }
    return camera;
}

void SunSettings::validate() const { checkFields(*this); }
void SkySettings::validate() const { checkFields(*this); }
void ImageSettings::validate() const
{
    checkFields(*this);
    require(pixelFilterWidth == 0.0 || pixelFilterWidth >= 1.0, "pixelFilterWidth",
            "a filter " + numberText(pixelFilterWidth) +
                " pixels wide would leave some samples out of every pixel: 0 (a box) or 1 to " +
                numberText(PixelFilter::kMaxWidth));
    require(shutterOpen <= shutterClose, "shutter",
            "the shutter closes (" + numberText(shutterClose) + ") before it opens (" + numberText(shutterOpen) + ")");
}
void ViewSettings::validate() const { checkFields(*this); }
void MediumSettings::validate() const { checkFields(*this); }
void MultipleScatteringSettings::validate() const { checkFields(*this); }
void IntegratorSettings::validate() const { checkFields(*this); }
void RenderSettings::validate() const { checkFields(*this); }

RenderSettings RenderSettings::at(double frame) const
{
    RenderSettings settings = atFrame(*this, frame);
    settings.camera = camera.at(frame);
    return settings;
}

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
