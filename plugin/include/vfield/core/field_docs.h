#pragma once
/// @file field_docs.h
/// The documentation tables of a struct's declared fields (`vfield help keys`).

#include <vfield/core/field_traits.h>

namespace vfield {

/// One key of a documentation table.
struct FieldDoc {
    std::string key;  ///< as in the file ("count"; "frames.start" inside a group)
    std::string type; ///< "number", "integer", "[x, y, z]", "\"a\" or \"b\"", "object", ...
    std::string defaultText;
    std::string meaning; ///< the doc line, with the unit and range
    std::string section; ///< for an object: the table that documents its keys
};

/// A table of keys: one per struct, titled by its place in the file.
struct FieldTable {
    std::string title; ///< "clouds[]", "objects[].mesh.terrain", ...
    std::vector<FieldDoc> rows;
};

namespace detail {
std::string numberDocText(double value);
std::string rangeDocText(double min, double max, bool isInteger);

template<typename T>
std::string typeDocText()
{
    if constexpr (std::is_same_v<T, double>) return "number";
    else if constexpr (kIsInteger<T>) return std::is_same_v<T, uint64_t> ? "integer >= 0" : "integer";
    else if constexpr (std::is_same_v<T, bool>) return "boolean";
    else if constexpr (std::is_same_v<T, std::string>) return "string";
    else if constexpr (std::is_same_v<T, Vec3d>) return "[x, y, z]";
    else if constexpr (std::is_same_v<T, Vec2d>) return "[x, z]";
    else if constexpr (std::is_same_v<T, Quatd>) return "[x, y, z] degrees";
    else if constexpr (std::is_same_v<T, BBoxd>) return "{\"min\", \"max\"}";
    else if constexpr (std::is_enum_v<T>) {
        std::string text;
        const std::vector<std::string> names = enumNameList<T>();
        for (std::size_t i = 0; i < names.size(); ++i)
            text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("`\"" + names[i] + "\"`");
        return text;
    } else if constexpr (IsVector<T>::value) return "array of " + typeDocText<typename T::value_type>();
    else return "object";
}

template<typename T>
std::string valueDocText(const T& value)
{
    if constexpr (std::is_same_v<T, double>) return "`" + numberDocText(value) + "`";
    else if constexpr (kComponents<T> > 0) {
        std::string text = "`[";
        for (int i = 0; i < kComponents<T>; ++i) text += (i ? ", " : "") + numberDocText(value[i]);
        return text + "]`";
    } else if constexpr (std::is_enum_v<T>) return std::string("`\"") + enumName(value) + "\"`";
    else if constexpr (std::is_same_v<T, std::string>) return "`\"" + value + "\"`";
    else {
        std::string text = leafToJson(value).dump();
        std::string spaced;
        for (const char c : text) spaced += c == ',' ? std::string(", ") : std::string(1, c);
        return "`" + spaced + "`";
    }
}
} // namespace detail

/// Gathers the documentation of a struct and the structs below it, from a
/// default-constructed value (its defaults): a table per object of the file.
class FieldDocumenter {
public:
    /// Appends the table `title` to tables; its nested objects' tables follow it.
    FieldDocumenter(std::vector<FieldTable>& tables, std::string title)
        : mTables(tables), mTable(tables.size()), mTitle(std::move(title))
    {
        mTables.push_back({mTitle, {}});
    }

    template<typename T>
    void operator()(const Field<T>& f)
    {
        using V = detail::Plain<T>;
        FieldDoc row;
        row.key = f.key();
        row.meaning = f.docText();
        describe(f, row, static_cast<V*>(nullptr));
        const std::string unitAndRange = unitAndRangeText(f, static_cast<V*>(nullptr));
        if (!unitAndRange.empty()) row.meaning += (row.meaning.empty() ? "" : "; ") + unitAndRange;
        if (f.defaultOverride()) row.defaultText = f.defaultOverride();
        if (f.isRequired()) row.defaultText = "required";
        if (f.selector()) row.defaultText = ""; // one alternative is given, none is the default
        if (f.keys()) row.type += " or keys";
        mTables[mTable].rows.push_back(std::move(row));
    }
    template<typename S>
    void operator()(const InlineFields<S>& section)
    {
        S::visitFields(*section.value, *this);
    }
    template<typename Declare>
    void operator()(const Group<Declare>& g)
    {
        FieldDoc row;
        row.key = g.key;
        row.type = "object";
        row.defaultText = "see its table";
        row.meaning = g.doc;
        row.section = childTitle(g.key);
        FieldDocumenter nested(mTables, row.section);
        g.declare(nested);
        mTables[mTable].rows.push_back(std::move(row));
    }

private:
    template<typename T, typename V>
    void describe(const Field<T>& f, FieldDoc& row, V*)
    {
        if constexpr (kHasFields<V>) {
            row.type = "object";
            row.defaultText = "see its table";
            row.section = childTitle(f.key());
            documentSection<V>(*f.ref(), row.section);
        } else if constexpr (detail::IsOptional<V>::value) {
            using Inner = typename V::value_type;
            if constexpr (kHasFields<Inner>) {
                row.type = f.acceptsBoolean() ? "object, `true` or `false`" : "object";
                row.defaultText = *f.ref() ? (f.acceptsBoolean() ? "`true` (its defaults)" : "see its table") : "none";
                row.section = childTitle(f.key());
                documentSection<Inner>(Inner{}, row.section);
            } else {
                row.type = detail::typeDocText<Inner>();
                row.defaultText = *f.ref() ? detail::valueDocText(**f.ref()) : "none";
            }
        } else if constexpr (detail::IsSectionList<V>::value) {
            row.type = "array of objects";
            row.defaultText = "`[]`";
            row.section = childTitle(f.key()) + "[]";
            documentSection<typename V::value_type>(typename V::value_type{}, row.section);
        } else if constexpr (detail::IsProxy<V>::value) {
            describeProxy(f.ref(), row);
        } else if constexpr (std::is_same_v<V, bool>) {
            row.type = f.trueName() ? "`\"" + std::string(f.falseName()) + "\"` or `\"" + f.trueName() + "\"`" : "boolean";
            row.defaultText = f.trueName() ? "`\"" + std::string(*f.ref() ? f.trueName() : f.falseName()) + "\"`"
                                           : (*f.ref() ? "`true`" : "`false`");
        } else {
            row.type = detail::typeDocText<V>();
            row.defaultText = detail::valueDocText(*f.ref());
        }
    }
    template<typename X>
    static void describeProxy(const PairRef<X>& pair, FieldDoc& row)
    {
        row.type = "[" + std::string(pair.names) + "]";
        row.defaultText =
            "`[" + stripTicks(detail::valueDocText(*pair.first)) + ", " + stripTicks(detail::valueDocText(*pair.second)) + "]`";
    }
    template<typename X>
    static void describeProxy(const UniformRef<X>& uniform, FieldDoc& row)
    {
        row.type = "number";
        row.defaultText = detail::valueDocText((*uniform.vector)[0]);
    }
    static std::string stripTicks(const std::string& text) { return text.substr(1, text.size() - 2); }

    template<typename T, typename V>
    static std::string unitAndRangeText(const Field<T>& f, V*)
    {
        using Value = std::conditional_t<detail::IsOptional<V>::value, typename detail::OptionalValue<V>::type, V>;
        std::string text = f.unitText();
        const std::string range = detail::rangeDocText(f.min(), f.max(), detail::kIsInteger<Value> || isIntegerProxy<Value>());
        if (!range.empty()) text += (text.empty() ? "" : ", ") + range;
        if (f.mustBeNonZero()) text += (text.empty() ? "" : ", ") + std::string("non-zero");
        return text;
    }
    template<typename V>
    static constexpr bool isIntegerProxy()
    {
        if constexpr (detail::IsPairRef<V>::value)
            return detail::kIsInteger<std::remove_const_t<typename detail::IsPairRef<V>::type>>;
        else return false;
    }

    /// "objects[].mesh": the place of a key's object in the file.
    std::string childTitle(const char* key) const { return mTitle == kSceneTitle ? std::string(key) : mTitle + "." + key; }
    template<typename S>
    void documentSection(const S& defaults, const std::string& title)
    {
        FieldDocumenter nested(mTables, title);
        S::visitFields(defaults, nested);
    }

    static constexpr const char* kSceneTitle = "scene";
    std::vector<FieldTable>& mTables;
    std::size_t mTable;
    std::string mTitle;
};

/// The documentation tables of T and the structs below it, from its
/// defaults; T's own table is titled "scene", the others by their place
/// ("objects[].mesh.terrain").
template<typename T>
std::vector<FieldTable> describeFields()
{
    std::vector<FieldTable> tables;
    const T defaults{};
    FieldDocumenter documenter(tables, "scene");
    T::visitFields(defaults, documenter);
    return tables;
}

/// A table as Markdown: | key | type | default | meaning |.
std::string markdownTable(const FieldTable& table);

} // namespace vfield
