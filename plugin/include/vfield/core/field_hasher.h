#pragma once
/// @file field_hasher.h
/// Every declared field of a struct into a content hash.

#include <vfield/core/field_traits.h>

namespace vfield {

/// Every declared field of a struct, nested ones included, into a content
/// hash, each behind its key (so that two fields cannot trade values
/// unseen). With file contents, a path field's file is hashed by its bytes.
class FieldHasher {
public:
    FieldHasher(ContentHash& hash, bool withFileContents) : mHash(hash), mWithFileContents(withFileContents) {}

    template<typename T>
    void operator()(const Field<T>& f)
    {
        // A field that does not apply (another alternative, a dynamic
        // object's key on a static one) shapes nothing.
        detail::hashLeaf(mHash, std::string(f.key()));
        mHash.addValue(int64_t(f.applies()));
        if (!f.applies()) return;
        hashValue(f, *pointer(f));
        if constexpr (detail::kKeyable<detail::Plain<T>>) {
            const KeyTrack* track = f.keys() ? f.keys()->find(f.key()) : nullptr;
            mHash.addValue(int64_t(track != nullptr));
            if (track) detail::hashKeyTrack(mHash, *track);
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
        detail::hashLeaf(mHash, std::string(g.key));
        g.declare(*this);
    }

private:
    template<typename T>
    static auto pointer(const Field<T>& f)
    {
        if constexpr (detail::IsProxy<detail::Plain<T>>::value) return &f.ref();
        else return f.ref();
    }

    template<typename T, typename X>
    void hashValue(const Field<T>& f, const X& value)
    {
        if constexpr (kHasFields<X>) {
            X::visitFields(value, *this);
        } else if constexpr (detail::IsOptional<X>::value) {
            mHash.addValue(int64_t(value.has_value()));
            if (value) hashValue(f, *value);
        } else if constexpr (detail::IsSectionList<X>::value) {
            mHash.addValue(uint64_t(value.size()));
            for (const auto& item : value) hashValue(f, item);
        } else if constexpr (detail::IsProxy<X>::value) {
            hashProxy(value);
        } else {
            detail::hashLeaf(mHash, value);
            if constexpr (std::is_same_v<X, std::string>)
                if (f.pathValued() && mWithFileContents) detail::hashLeaf(mHash, readFileBytes(value));
        }
    }
    template<typename X>
    void hashProxy(const PairRef<X>& pair)
    {
        detail::hashLeaf(mHash, *pair.first);
        detail::hashLeaf(mHash, *pair.second);
    }
    template<typename X>
    void hashProxy(const UniformRef<X>& uniform)
    {
        detail::hashLeaf(mHash, *uniform.vector);
    }

    ContentHash& mHash;
    bool mWithFileContents;
};

/// Adds every declared field of value to hash; with file contents, the bytes
/// of the files its path fields name (FileError when one cannot be read).
template<typename T>
void hashFields(ContentHash& hash, const T& value, bool withFileContents = false)
{
    FieldHasher hasher(hash, withFileContents);
    T::visitFields(value, hasher);
}

} // namespace vfield
