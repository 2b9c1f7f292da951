// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include "mesh/scene/input_error.h"
#include "solver/reference/reference_csv.h"
#include "test_util.h"

using namespace bounce;

TEST(ReferenceCsv, ColumnsByNameOthersKeptQuotedFieldsRoundTrip) {
    test::TempDir dir;
    const auto p = dir.write("in.csv",
                             "id,nz,ny,nx,z,y,x,label\n"
                             "1,1,0,0,3,2,1,\"a, b\"\n"
                             "2, 0 ,1,0,6,5,4,\"say \"\"hi\"\"\"\n");
    const CsvTable t = read_csv(p);
    ASSERT_EQ(t.rows.size(), 2u);
    EXPECT_EQ(t.rows[0][7], "a, b");
    EXPECT_EQ(t.rows[1][7], "say \"hi\"");
    const auto rows = point_rows(t, p);
    EXPECT_EQ(rows[0].position, glm::dvec3(1, 2, 3));
    EXPECT_EQ(rows[1].normal, glm::dvec3(0, 1, 0));
    const auto back = dir.write("back.csv", to_csv(t));
    const CsvTable u = read_csv(back);
    EXPECT_EQ(u.rows, t.rows);
    EXPECT_EQ(u.header, t.header);
}

TEST(ReferenceCsv, BadRowsAreRefusedNamingFileLineAndColumn) {
    test::TempDir dir;
    auto message = [&](const std::string& text) {
        const auto p = dir.write("bad.csv", text);
        try {
            point_rows(read_csv(p), p);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(message("x,y,z,nx,ny,nz\n0,0,0,0,0,1\n0,nan,0,0,0,1\n").find("bad.csv:3: column y: not a finite number"),
              std::string::npos);
    EXPECT_NE(message("x,y,z,nx,ny\n0,0,0,0,0\n").find("no column 'nz'"), std::string::npos);
    EXPECT_NE(message("x,y,z,nx,ny,nz\n0,0,0,0,0,1\n0,0\n").find("bad.csv:3: 2 fields, expected 6"), std::string::npos);
    EXPECT_NE(message("x,y,z,nx,ny,nz\n0,0,zero,0,0,1\n").find("bad.csv:2: column z: not a number, got 'zero'"),
              std::string::npos);
    EXPECT_NE(message("x,y,z,nx,ny,nz\n0,0,0,0,0,0\n").find("bad.csv:2: the normal (nx,ny,nz) is zero"),
              std::string::npos);
    EXPECT_NE(message("").find("empty CSV file"), std::string::npos);
    EXPECT_NE(message("x,y,z,nx,ny,nz\n").find("no points"), std::string::npos);
}
