// SPDX-License-Identifier: Apache-2.0
// For the status page's tests: the text of an HTML element found by its id (tags stripped, the
// entities the page and Chromium's DOM dump write decoded), read without the page's own code.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>

namespace mogao::status_page_test {

inline std::string decode_entities(const std::string& s) {
    static const std::pair<const char*, const char*> kEntities[] = {
        {"&amp;", "&"}, {"&lt;", "<"},          {"&gt;", ">"},  {"&quot;", "\""},
        {"&#39;", "'"}, {"&#215;", "\xC3\x97"}, {"&nbsp;", " "}};
    std::string out;
    for (std::size_t i = 0; i < s.size();) {
        bool done = false;
        for (const auto& [from, to] : kEntities) {
            const std::string f = from;
            if (s.compare(i, f.size(), f) == 0) {
                out += to;
                i += f.size();
                done = true;
                break;
            }
        }
        if (!done) out.push_back(s[i++]);
    }
    return out;
}

// The text inside the element whose opening tag holds id="ID" (nested tags stripped); nullopt when
// no element has it.
inline std::optional<std::string> element_text(const std::string& html, const std::string& id) {
    const std::size_t at = html.find("id=\"" + id + "\"");
    if (at == std::string::npos) return std::nullopt;
    std::size_t i = html.find('>', at);
    if (i == std::string::npos) return std::nullopt;
    int depth = 1;
    std::string text;
    for (++i; i < html.size() && depth > 0;) {
        if (html[i] != '<') {
            text.push_back(html[i++]);
            continue;
        }
        const std::size_t end = html.find('>', i);
        if (end == std::string::npos) break;
        const std::string tag = html.substr(i, end - i + 1);
        if (tag.rfind("</", 0) == 0) {
            --depth;
        } else if (tag.find("<br") != 0 && tag.find("<img") != 0 && tag[tag.size() - 2] != '/') {
            ++depth;
        }
        i = end + 1;
    }
    return decode_entities(text);
}

}  // namespace mogao::status_page_test
