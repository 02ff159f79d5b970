// SPDX-License-Identifier: Apache-2.0
// mogao_kiosk_config_reference: the kiosk configuration's reference table (kiosk_config_schema.h) in
// docs/kiosk.md, between "<!-- generated:kiosk-config-reference -->" and "<!-- /generated -->".
//   mogao_kiosk_config_reference                 print the table
//   mogao_kiosk_config_reference --write FILE    rewrite FILE's block
//   mogao_kiosk_config_reference --check FILE    exit 1 if FILE's block is not the table (CTest
//                                                kiosk_config_reference_current)
// Not installed: a build tool.
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include "kiosk/config/kiosk_config_schema.h"

namespace {

constexpr std::string_view kBegin = "<!-- generated:kiosk-config-reference -->\n";
constexpr std::string_view kEnd = "<!-- /generated -->";

int run(const std::string& mode, const std::string& file) {
    std::string text;
    {
        std::ifstream in(file, std::ios::binary);
        if (!in) {
            std::cerr << file << ": cannot open\n";
            return 2;
        }
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    const auto begin = text.find(kBegin);
    const auto end = begin == std::string::npos ? begin : text.find(kEnd, begin);
    if (end == std::string::npos) {
        std::cerr << file << ": no " << kBegin.substr(0, kBegin.size() - 1) << " ... " << kEnd << " block\n";
        return 2;
    }
    const std::string now = text.substr(begin + kBegin.size(), end - begin - kBegin.size());
    const std::string table = mogao::config_reference_markdown();
    if (mode == "--check") {
        if (now == table) return 0;
        std::cerr << file << ": the kiosk configuration reference is stale; regenerate it with\n"
                  << "  build/kiosk/mogao_kiosk_config_reference --write " << file << "\n";
        return 1;
    }
    std::ofstream(file, std::ios::binary) << text.substr(0, begin + kBegin.size()) << table << text.substr(end);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc == 1) {
        std::cout << mogao::config_reference_markdown();
        return 0;
    }
    const std::string mode = argv[1];
    if (argc != 3 || (mode != "--check" && mode != "--write")) {
        std::cerr << "usage: mogao_kiosk_config_reference [--check FILE | --write FILE]\n";
        return 2;
    }
    return run(mode, argv[2]);
}
