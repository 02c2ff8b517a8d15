#include <vfield/core/field_visitors.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace vfield {

namespace detail {

Vec3d eulerDegrees(const Quatd& rotation)
{
    // rotationFromDegrees composes z * y * x: the matrix Rz Ry Rx, whose
    // elements give the angles back (y within [-90, 90] degrees).
    const Quatd q = rotation.unit();
    const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
    const double r20 = 2.0 * (x * z - w * y), r21 = 2.0 * (y * z + w * x), r22 = 1.0 - 2.0 * (x * x + y * y);
    const double r10 = 2.0 * (x * y + w * z), r00 = 1.0 - 2.0 * (y * y + z * z);
    const double toDegrees = 180.0 / M_PI;
    return Vec3d(std::atan2(r21, r22), std::asin(std::clamp(-r20, -1.0, 1.0)), std::atan2(r10, r00)) * toDegrees;
}

std::string numberDocText(double value)
{
    std::ostringstream text;
    text << value;
    std::string out = text.str();
    // 1e+12 and 1e-09 read as 1e12 and 1e-9 in the tables.
    const std::size_t e = out.find('e');
    if (e == std::string::npos) return out;
    std::string exponent = out.substr(e + 1);
    const bool negative = exponent[0] == '-';
    exponent.erase(0, exponent.find_first_not_of("+-0"));
    return out.substr(0, e + 1) + (negative ? "-" : "") + exponent;
}

std::string rangeDocText(double min, double max, bool isInteger)
{
    const auto text = [isInteger](double v) {
        return isInteger && std::abs(v) < 1e15 ? std::to_string(static_cast<long long>(v)) : numberDocText(v);
    };
    const bool hasMin = std::isfinite(min), hasMax = std::isfinite(max);
    if (hasMin && hasMax) return text(min) + ".." + text(max);
    if (hasMin) return ">= " + text(min);
    if (hasMax) return "<= " + text(max);
    return "";
}

} // namespace detail

std::string FieldReader::resolvePath(const std::string& path) const
{
    const std::filesystem::path file(path);
    return file.is_absolute() || mBaseDir.empty() ? file.string() : (std::filesystem::path(mBaseDir) / file).string();
}

std::string markdownTable(const FieldTable& table)
{
    std::string text = "| key | type | default | meaning |\n|---|---|---|---|\n";
    for (const FieldDoc& row : table.rows) {
        std::string meaning = row.meaning;
        if (!row.section.empty()) meaning += (meaning.empty() ? "" : "; ") + std::string("keys: `") + row.section + "`";
        // A | inside a cell would end it.
        std::string escaped;
        for (const char c : meaning) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
        text += "| `" + row.key + "` | " + row.type + " | " + row.defaultText + " | " + escaped + " |\n";
    }
    return text;
}

} // namespace vfield
