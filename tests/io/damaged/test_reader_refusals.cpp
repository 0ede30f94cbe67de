// The result reader's refusals, in process: every damaged-file case of the command line's and
// the analysis scripts' table (tests/hardening/damages.py: wrong types and shapes, missing and
// contradictory attributes, values out of range, truncations, flipped bits, files that are not
// superball's), each file written by make_damaged_files.py (a ctest fixture) and listed in
// $SUPERBALL_DAMAGED_FILES (its cases.json). Opening and reading the file as `superball info`
// does (ResultReader, then every value through outcome_counts) throws FormatError, whose one
// line names the file and the object; no other exception, no crash, and the file is left as
// it was.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/result_reader.hpp"

namespace superball {
namespace {

namespace fs = std::filesystem;

std::string bytes_of(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(ReaderRefusals, EveryDamageIsOneFormatErrorNamingTheFileAndTheObject)
{
    const char* list = std::getenv("SUPERBALL_DAMAGED_FILES");
    if (list == nullptr) GTEST_SKIP() << "SUPERBALL_DAMAGED_FILES is not set: run through ctest (io.reader_refusals)";
    std::ifstream in(list);
    ASSERT_TRUE(in) << "cannot read " << list;
    const nlohmann::json cases = nlohmann::json::parse(in);
    ASSERT_GE(cases.size(), 100u);
    for (const nlohmann::json& c : cases) {
        const std::string what = c.at("what"), path = c.at("path");
        SCOPED_TRACE(what + " (" + c.at("base").get<std::string>() + "): " + path);
        std::error_code ec;
        const bool regular = fs::is_regular_file(path, ec);
        const std::string before = regular ? bytes_of(path) : std::string();
        try {
            const ResultReader reader(path);
            reader.outcome_counts();
            ADD_FAILURE() << "read without a refusal";
        } catch (const FormatError& e) {
            const std::string message = e.what();
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
            EXPECT_NE(message.find(path), std::string::npos) << "does not name the file: " << message;
            bool names_it = false;
            for (const std::string expected : c.at("expected")) names_it = names_it || message.find(expected) != std::string::npos;
            EXPECT_TRUE(names_it) << message << "\n  expected one of: " << c.at("expected").dump();
        } catch (const std::exception& e) {
            ADD_FAILURE() << "not a FormatError: " << e.what();
        }
        if (regular) {
            EXPECT_EQ(bytes_of(path), before) << "the reader changed the file";
        }
    }
}

}  // namespace
}  // namespace superball
