#include <vfield/scene/scene_keys.h>

#include <vfield/scene/scene.h>

#include <set>

namespace vfield {

std::vector<FieldTable> sceneKeyTables() { return describeFields<Scene>(); }

KeyTableUpdate updateKeyTables(const std::string& document, const std::vector<FieldTable>& tables)
{
    static const std::string kBegin = "<!-- keys: ", kEnd = "<!-- end keys -->";
    KeyTableUpdate update;
    std::set<std::string> present;
    std::size_t at = 0;
    for (;;) {
        const std::size_t begin = document.find(kBegin, at);
        if (begin == std::string::npos) break;
        const std::size_t titleEnd = document.find(" -->", begin);
        const std::size_t end = titleEnd == std::string::npos ? std::string::npos : document.find(kEnd, titleEnd);
        if (end == std::string::npos) break; // an unclosed marker is left as it is
        const std::string title = document.substr(begin + kBegin.size(), titleEnd - begin - kBegin.size());
        const std::size_t bodyStart = titleEnd + 4 + 1; // past " -->\n"
        update.text += document.substr(at, bodyStart - at);
        const std::string body = document.substr(bodyStart, end - bodyStart);
        const auto table = std::find_if(tables.begin(), tables.end(), [&](const FieldTable& t) { return t.title == title; });
        if (table == tables.end()) {
            update.unknown.push_back(title);
            update.text += body;
        } else {
            present.insert(title);
            const std::string current = markdownTable(*table);
            if (body != current) update.stale.push_back(title);
            update.text += current;
        }
        at = end;
    }
    update.text += document.substr(at);
    for (const FieldTable& table : tables)
        if (!present.count(table.title)) update.absent.push_back(table.title);
    return update;
}

} // namespace vfield
