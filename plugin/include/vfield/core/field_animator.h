#pragma once
/// @file field_animator.h
/// A struct at one frame: every keyed member (animation.h) set to its value
/// there, and constant from then on.

#include <vfield/core/field_traits.h>

namespace vfield {

/// Sets each keyed member of a struct, nested structs' included, to its
/// value at one frame.
class FieldAnimator {
public:
    explicit FieldAnimator(double frame) : mFrame(frame) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        using V = detail::Plain<T>;
        if constexpr (kHasFields<V>) {
            V::visitFields(*f.ref(), *this);
        } else if constexpr (detail::IsSectionList<V>::value) {
            for (auto& item : *f.ref()) V::value_type::visitFields(item, *this);
        } else if constexpr (detail::IsOptional<V>::value && kHasFields<typename detail::OptionalValue<V>::type>) {
            if (*f.ref()) V::value_type::visitFields(**f.ref(), *this);
        } else if constexpr (detail::kKeyable<V>) {
            if (const KeyTrack* track = f.animation() ? f.animation()->find(f.key()) : nullptr) {
                *f.ref() = keyedValue<detail::KeyedValue<V>>(*track, mFrame);
                f.animation()->erase(f.key());
            }
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
        g.declare(*this);
    }

private:
    double mFrame;
};

/// value with every keyed member, nested ones included, at frame: a struct
/// without keys, as a scene file holding these constants would give.
template<typename T>
T atFrame(T value, double frame)
{
    FieldAnimator animator(frame);
    T::visitFields(value, animator);
    return value;
}

} // namespace vfield
