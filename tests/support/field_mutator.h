#pragma once
// Changes one declared field of an options struct (vfield/core/fields.h),
// chosen by its place in the declaration's order, so that a test can walk
// every field that applies and see what each one reaches.

#include <vfield/core/field_visitors.h>

#include <string>

namespace vfield::test {

class FieldMutator {
public:
    /// Changes the target-th field that applies (0-based, in declaration
    /// order, nested structs' fields in place); paths to files are left
    /// alone (their bytes are what counts).
    explicit FieldMutator(int target) : mTarget(target) {}

    /// Fields seen so far; after visiting a whole struct, how many there are.
    int count() const { return mCount; }
    bool changed() const { return !mChanged.empty(); }
    const std::string& changedKey() const { return mChanged; }

    template<typename T>
    void operator()(const Field<T>& f)
    {
        if (!f.applies() || f.pathValued()) return;
        using V = std::remove_const_t<T>;
        if constexpr (kHasFields<V>) {
            enter(f.key(), *f.ref());
        } else if constexpr (detail::IsOptional<V>::value) {
            using Inner = typename V::value_type;
            if (claim(f.key())) {
                if constexpr (kHasFields<Inner>) { // a section present becomes absent, an absent one present
                    if (*f.ref()) f.ref()->reset();
                    else f.ref()->emplace();
                } else if (*f.ref()) {
                    changeLeaf(**f.ref());
                } else {
                    f.ref()->emplace();
                }
            }
            if constexpr (kHasFields<Inner>)
                if (*f.ref()) enter(f.key(), **f.ref());
        } else if constexpr (detail::IsSectionList<V>::value) {
            for (auto& item : *f.ref()) enter(f.key(), item);
            if (claim(f.key())) f.ref()->emplace_back();
        } else if constexpr (detail::IsPairRef<V>::value) {
            if (claim(std::string(f.key()) + "/0")) changeLeaf(*f.ref().first);
            if (claim(std::string(f.key()) + "/1")) changeLeaf(*f.ref().second);
        } else if constexpr (detail::IsProxy<V>::value) {
            if (claim(f.key())) changeLeaf(*f.ref().vector);
        } else {
            if (claim(f.key())) changeLeaf(*f.ref());
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
    template<typename S>
    void enter(const std::string&, S& section)
    {
        S::visitFields(section, *this);
    }
    bool claim(const std::string& key)
    {
        if (mCount++ != mTarget) return false;
        mChanged = key;
        return true;
    }
    template<typename X>
    static void changeLeaf(X& value)
    {
        if constexpr (std::is_same_v<X, bool>) value = !value;
        else if constexpr (std::is_same_v<X, std::string>) value += "x";
        else if constexpr (detail::kComponents<X> > 0) value[0] += 1.0;
        else if constexpr (std::is_enum_v<X>) {
            const auto names = enumNameList<X>();
            std::size_t index = 0;
            while (names[index] != enumName(value)) ++index;
            value = *enumFromName<X>(names[(index + 1) % names.size()]);
        } else if constexpr (std::is_same_v<X, Quatd>) value = (value * Quatd(Vec3d(0, 1, 0), 0.25)).unit();
        else if constexpr (std::is_same_v<X, BBoxd>) value.max() += Vec3d(1.0);
        else if constexpr (detail::IsVector<X>::value) value.emplace_back();
        else if constexpr (std::is_floating_point_v<X>) value = value * 1.5 + 0.25;
        else value += 1;
    }

    int mTarget, mCount = 0;
    std::string mChanged;
};

/// How many fields of value apply (what FieldMutator can change).
template<typename T>
int countFields(T value)
{
    FieldMutator counter(-1);
    T::visitFields(value, counter);
    return counter.count();
}

/// value with its target-th field changed; key names it.
template<typename T>
T withFieldChanged(T value, int target, std::string& key)
{
    FieldMutator mutator(target);
    T::visitFields(value, mutator);
    key = mutator.changedKey();
    return value;
}

} // namespace vfield::test
