#pragma once
/// @file field_writer.h
/// A struct written as a scene file holds it, from its declaration.

#include <vfield/core/field_traits.h>

namespace vfield {

/// A struct as a scene file writes it: every field that applies, into a
/// nlohmann::json (keys sorted) or nlohmann::ordered_json (keys in the
/// declaration's order).
template<typename Json>
class FieldWriter {
public:
    explicit FieldWriter(Json& object) : mObject(object) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        if (!f.applies()) return;
        using V = detail::Plain<T>;
        if constexpr (detail::kKeyable<V>) {
            if (const KeyTrack* track = f.keys() ? f.keys()->find(f.key()) : nullptr) {
                mObject[f.key()] = Json(detail::keyTrackToJson<detail::KeyedValue<V>>(*track));
                return;
            }
        }
        if constexpr (detail::IsProxy<V>::value) {
            mObject[f.key()] = proxyToJson(f.ref());
        } else if constexpr (detail::IsOptional<V>::value) {
            if (*f.ref()) mObject[f.key()] = valueToJson(**f.ref());
            else if (f.acceptsBoolean()) mObject[f.key()] = false;
        } else if constexpr (std::is_same_v<V, bool>) {
            mObject[f.key()] = f.trueName() ? Json(*f.ref() ? f.trueName() : f.falseName()) : Json(*f.ref());
        } else {
            mObject[f.key()] = valueToJson(*f.ref());
        }
    }
    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        S::visitFields(*section.value, *this);
    }
    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        Json nested = Json::object();
        FieldWriter writer(nested);
        g.declare(writer);
        mObject[g.key] = nested;
    }

private:
    template<typename X>
    static Json valueToJson(const X& value)
    {
        if constexpr (kHasFields<X>) {
            Json object = Json::object();
            FieldWriter writer(object);
            X::visitFields(value, writer);
            return object;
        } else if constexpr (detail::IsSectionList<X>::value) {
            Json array = Json::array();
            for (const auto& item : value) array.push_back(valueToJson(item));
            return array;
        } else {
            return Json(detail::leafToJson(value));
        }
    }
    template<typename X>
    static Json proxyToJson(const PairRef<X>& pair)
    {
        return {*pair.first, *pair.second};
    }
    template<typename X>
    static Json proxyToJson(const UniformRef<X>& uniform)
    {
        return (*uniform.vector)[0];
    }

    Json& mObject;
};

/// The struct's fields that apply, as a JSON object a scene file could hold;
/// with Json = nlohmann::ordered_json, in the declaration's order.
template<typename T, typename Json = nlohmann::json>
Json fieldsToJson(const T& value)
{
    Json object = Json::object();
    FieldWriter<Json> writer(object);
    T::visitFields(value, writer);
    return object;
}

} // namespace vfield
