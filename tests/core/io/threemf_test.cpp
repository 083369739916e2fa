// 3MF: zip container (stored and deflated entries, relationships), mesh objects, components and
// build items with transforms, units, and errors. 3MF needs zlib at build time; without it
// the reader answers "unsupported", which one test checks and the others skip on.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>

namespace lamina {
namespace {

using test::find_note;
using test::make_zip;
using test::stored;
using test::TempDir;
using test::ZipItem;

using test::kContentTypes;
using test::model;
using test::package;
using test::rels;

using test::kTriangleObject;

// `translate([1,2,3]) cube([10,20,30]);` exported by OpenSCAD 2021.01 (lib3mf 1.8.1, Debian
// bookworm): lib3mf writes ZIP64 end records and ZIP64 extra fields, and namespaced attributes.
const std::string_view kLib3mfCube(
      "\x50\x4b\x03\x04\x2d\x00\x00\x00\x08\x00\x00\x00\x00\x00\x9a\x34\xfb\x81\xff\xff\xff\xff\xff\xff\xff\xff\x10\x00"
      "\x14\x00\x33\x44\x2f\x33\x64\x6d\x6f\x64\x65\x6c\x2e\x6d\x6f\x64\x65\x6c\x01\x00\x10\x00\xbd\x06\x00\x00\x00\x00"
      "\x00\x00\x39\x02\x00\x00\x00\x00\x00\x00\x9d\x55\xcb\x8e\x9b\x30\x14\x5d\x27\x5f\x61\x79\xef\x98\x77\x48\x64\x32"
      "\xaa\x3a\x9b\x2e\xaa\x2e\x46\xf9\x00\x63\xcc\x84\x0a\x03\x02\x13\x65\xfa\xf5\xbd\x36\x90\x34\x9a\x84\x11\x65\xe5"
      "\xc7\xb9\xe7\xdc\x87\xef\x85\xbd\x5c\x54\x89\xce\xb2\xed\x8a\xba\x4a\xb0\xbb\x71\x30\x92\x95\xa8\xb3\xa2\x7a\x4f"
      "\x70\xaf\x73\x12\xe3\x97\xc3\x9a\xa9\x3a\x93\x25\x02\x6c\xd5\x25\xf8\xa4\x75\xb3\xa7\xb4\x13\x27\xa9\x78\xb7\x51"
      "\x85\x68\xeb\xae\xce\xf5\x46\xd4\x8a\xfa\x99\xe2\x55\x9f\x73\xa1\xfb\x16\x48\xa8\xa8\x5b\x49\x3d\xc7\x0d\xa9\xe3"
      "\x61\xd4\x57\x85\x4e\xb0\x2a\xca\xb2\x50\x52\xcb\x16\x1b\xce\x7d\xc9\x8d\x9a\xac\xc8\xf1\xcd\x1e\x54\xdd\x5e\x2d"
      "\x94\x51\x1c\xd8\x0a\x5e\xde\xa4\xac\xb3\xfb\x66\x21\x4f\xd3\xd6\x59\x2f\x34\x64\x63\x64\x8a\x26\x8f\xd2\x85\x4c"
      "\xa9\xe4\xaa\xe4\x5a\x17\xc2\xc6\xbf\xb5\xf1\x0f\x4e\x2d\xcd\x61\x57\x8e\x24\x90\xc4\x2d\x3e\xac\x57\xac\x95\x5d"
      "\xdd\xb7\x42\x76\xb0\x59\xb1\x3a\xfd\x2d\x85\x46\x45\x06\x15\xc4\xa8\xe2\x4a\x26\xf8\x57\x23\xab\xb7\xef\xdf\x5e"
      "\xd1\x4f\x53\x3a\x8c\xf4\x47\x03\xa7\xb6\x8e\x18\x35\xfb\xe3\xf1\xc7\x6b\x82\xc3\xd8\xe5\x71\xec\xe7\x44\x88\xd4"
      "\x21\x81\xef\x48\xc2\x73\x1e\x13\xe1\xc6\x32\x95\x91\xeb\xef\x32\xab\x07\x1a\x4a\x76\x27\x23\x06\x4b\x78\x2e\x26"
      "\x2a\xab\x3d\xed\xe5\x05\x5d\xec\xfb\x71\xcc\x87\xd1\x47\x82\xbd\x8d\x5d\xc3\xe6\x4f\x82\xfd\xeb\x86\x0e\x2c\x03"
      "\xcd\x97\x66\x0b\xec\xfe\x57\xef\xde\x6e\x5e\x10\x1a\xc4\x7e\x4b\x03\x9c\xb1\x5b\x22\x78\xef\xea\xd5\x97\x47\x29"
      "\xbd\x57\xbc\x37\xfc\x24\xc9\xe8\x7d\x4d\x99\x86\x5e\xaa\xde\xcb\x5b\x8d\xa7\x03\x74\x76\x13\x0c\x25\x3d\x7b\xf6"
      "\xad\x9d\x7d\x28\x2d\x46\x57\x07\x1e\xc1\xa0\xed\x0d\x0c\x1a\x69\x16\x06\x34\x06\x06\xe8\x59\x58\x30\xc0\xc2\x2f"
      "\x60\x70\x6f\xd8\xa0\x1d\x66\xd9\xc0\x29\x03\x03\xd2\xc7\x30\xb0\x37\x91\x8e\x6c\x4f\x23\x35\x21\x02\x6c\x0c\xe1"
      "\x69\xa4\xe6\xfe\xc6\xb6\x7d\x26\x3a\xc2\xe0\x7e\x36\x6f\x26\x13\xc0\x36\x86\xf0\x34\x21\xc6\xf7\x1b\xec\x26\xca"
      "\xe8\x54\xac\xa1\x91\x19\x9d\x5a\x9c\xd1\x61\xa0\x98\x41\x43\xff\x9d\x34\x2c\xed\x8b\x32\xbb\x4e\x8f\x38\xf4\x43"
      "\x2e\x82\x08\xc6\x85\xe7\x93\x80\xa7\x11\xd9\x79\x6e\x46\x3c\x9f\xcb\x3c\x0a\x76\x70\x10\x98\x69\xb5\x62\x85\x96"
      "\x0a\x0d\xa4\xe3\x90\x9a\x26\x10\xdf\xca\xd0\xf7\xdc\x94\x64\x91\xcb\x49\x20\x76\x5b\x92\x86\x39\xcc\xa2\x0c\x66"
      "\x4f\x14\xfb\xbe\xeb\xf2\x21\x4f\x8c\x5a\x75\xf8\x19\x51\x3b\xc5\x0e\xeb\xbf\x50\x4b\x03\x04\x2d\x00\x00\x00\x08"
      "\x00\x00\x00\x00\x00\xa1\x0a\x78\x08\xff\xff\xff\xff\xff\xff\xff\xff\x13\x00\x14\x00\x5b\x43\x6f\x6e\x74\x65\x6e"
      "\x74\x5f\x54\x79\x70\x65\x73\x5d\x2e\x78\x6d\x6c\x01\x00\x10\x00\x51\x02\x00\x00\x00\x00\x00\x00\xeb\x00\x00\x00"
      "\x00\x00\x00\x00\x9d\x52\x4d\x4a\xc5\x30\x10\x5e\xdb\x53\x84\x6c\xa5\x4d\x55\x10\x91\xb6\x6f\xa1\xde\xc0\x0b\x84"
      "\x74\xfa\xa3\xc9\x24\x24\xd3\x47\xbd\xbd\xd3\x56\x1e\x28\xd6\x82\xcb\xc9\xcc\xf7\x4b\xaa\xd3\xec\xac\x38\x43\x4c"
      "\xa3\xc7\x5a\xde\x14\xa5\x14\x80\xc6\xb7\x23\xf6\xb5\x9c\xa8\xcb\x1f\xe4\xa9\xc9\xaa\xd7\x8f\x00\x49\xf0\x2d\xa6"
      "\x5a\x0e\x44\xe1\x51\xa9\x64\x06\x70\x3a\x15\x3e\x00\xf2\xa6\xf3\xd1\x69\xe2\x31\xf6\x2a\x68\xf3\xae\x7b\x50\xb7"
      "\x65\x79\xaf\x8c\x47\x02\xa4\x9c\x16\x0e\xd9\x64\x57\xd5\x33\x74\x7a\xb2\x24\x5e\x66\x5e\x6c\xca\x6f\x01\x7a\x29"
      "\x9e\xb6\xd3\x45\xad\x96\xa3\x5b\x28\xb6\x85\xda\x85\xfd\x07\xe5\x7c\x0b\xf6\x87\x9a\x0e\xc1\x8e\x46\x13\xf7\xa0"
      "\xce\xd8\x16\x2e\xe5\x5f\x29\x8a\xbb\xd6\x69\x9c\x3a\x6d\x68\x8a\xdc\x4b\xce\xf3\x42\x70\xcd\xa1\xa5\xd8\x73\x16"
      "\xf0\x77\x67\xeb\xfb\x1e\x28\x82\x4d\x07\xbe\xbe\xb7\x7d\xf1\xc8\xc8\xd5\x7b\x1a\xc6\x90\xfe\x76\x46\x30\x73\x10"
      "\x38\xd0\x39\xce\x7f\xe1\xe1\x34\x95\x5a\x7f\x48\x93\x7d\x02\x50\x4b\x03\x04\x2d\x00\x00\x00\x08\x00\x00\x00\x00"
      "\x00\x3e\xcd\xa5\x4e\xff\xff\xff\xff\xff\xff\xff\xff\x0b\x00\x14\x00\x5f\x72\x65\x6c\x73\x2f\x2e\x72\x65\x6c\x73"
      "\x01\x00\x10\x00\x08\x01\x00\x00\x00\x00\x00\x00\xb2\x00\x00\x00\x00\x00\x00\x00\x65\x8f\xcd\x0a\xc2\x30\x10\x84"
      "\xcf\xf6\x29\xc2\xde\xed\xb6\x16\x44\xc4\xb4\x17\x2f\x5e\xa5\x2f\x10\xd2\xed\x0f\x36\x3f\x24\xa9\xe8\xdb\xbb\x82"
      "\x82\xc5\xe3\xce\xcc\x7e\xcc\x9c\x9a\x87\x99\xc5\x9d\x42\x9c\x9c\x95\x50\xe6\x05\x08\xb2\xda\x75\x93\x1d\x24\x2c"
      "\xa9\xdf\x1e\xa0\xa9\xb3\xd3\x95\x66\x95\x38\x12\xc7\xc9\x47\xc1\x3f\x36\x4a\x18\x53\xf2\x47\xc4\xa8\x47\x32\x2a"
      "\xe6\xce\x93\x65\xa7\x77\xc1\xa8\xc4\x67\x18\xd0\x2b\x7d\x53\x03\xe1\xae\x28\xf6\x18\x7e\x19\x50\x67\x9b\x15\x55"
      "\xb4\x4f\x4f\x7f\x4c\x33\xe9\xe0\xa2\xeb\x53\xae\x9d\xc1\xaa\x33\xca\x2e\xbd\xd2\x69\x09\x5c\x90\xb1\x65\x85\x45"
      "\xf9\xd6\x5d\x47\x33\x88\x56\x85\x81\x92\x04\xac\xce\x5f\x31\xff\x58\x97\x4e\x02\x37\xe0\x7d\xc8\x7b\x70\x35\xa8"
      "\xce\x5e\x50\x4b\x01\x02\x2d\x00\x2d\x00\x00\x00\x08\x00\x00\x00\x00\x00\x9a\x34\xfb\x81\xff\xff\xff\xff\xff\xff"
      "\xff\xff\x10\x00\x1c\x00\x00\x00\x00\x00\x00\x00\x80\x00\x00\x00\xff\xff\xff\xff\x33\x44\x2f\x33\x64\x6d\x6f\x64"
      "\x65\x6c\x2e\x6d\x6f\x64\x65\x6c\x01\x00\x18\x00\xbd\x06\x00\x00\x00\x00\x00\x00\x39\x02\x00\x00\x00\x00\x00\x00"
      "\x00\x00\x00\x00\x00\x00\x00\x00\x50\x4b\x01\x02\x2d\x00\x2d\x00\x00\x00\x08\x00\x00\x00\x00\x00\xa1\x0a\x78\x08"
      "\xff\xff\xff\xff\xff\xff\xff\xff\x13\x00\x1c\x00\x00\x00\x00\x00\x00\x00\x80\x00\x00\x00\xff\xff\xff\xff\x5b\x43"
      "\x6f\x6e\x74\x65\x6e\x74\x5f\x54\x79\x70\x65\x73\x5d\x2e\x78\x6d\x6c\x01\x00\x18\x00\x51\x02\x00\x00\x00\x00\x00"
      "\x00\xeb\x00\x00\x00\x00\x00\x00\x00\x7b\x02\x00\x00\x00\x00\x00\x00\x50\x4b\x01\x02\x2d\x00\x2d\x00\x00\x00\x08"
      "\x00\x00\x00\x00\x00\x3e\xcd\xa5\x4e\xff\xff\xff\xff\xff\xff\xff\xff\x0b\x00\x1c\x00\x00\x00\x00\x00\x00\x00\x80"
      "\x00\x00\x00\xff\xff\xff\xff\x5f\x72\x65\x6c\x73\x2f\x2e\x72\x65\x6c\x73\x01\x00\x18\x00\x08\x01\x00\x00\x00\x00"
      "\x00\x00\xb2\x00\x00\x00\x00\x00\x00\x00\xab\x03\x00\x00\x00\x00\x00\x00\x50\x4b\x06\x06\x2c\x00\x00\x00\x00\x00"
      "\x00\x00\x2d\x00\x2d\x00\x00\x00\x00\x00\x00\x00\x00\x00\x03\x00\x00\x00\x00\x00\x00\x00\x03\x00\x00\x00\x00\x00"
      "\x00\x00\x0c\x01\x00\x00\x00\x00\x00\x00\x9a\x04\x00\x00\x00\x00\x00\x00\x50\x4b\x06\x07\x00\x00\x00\x00\xa6\x05"
      "\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00\x50\x4b\x05\x06\x00\x00\x00\x00\x03\x00\x03\x00\x0c\x01\x00\x00\xff\xff"
      "\xff\xff\x00\x00",
      1544);

bool three_mf_compiled() {
  auto r = parse_3mf(package(model(kTriangleObject, "<item objectid=\"1\"/>\n")), "probe.3mf");
  return !(!r && r.error().code == ErrorCode::unsupported);
}

#define SKIP_WITHOUT_3MF()                                                                              \
  if (!three_mf_compiled())                                                                              \
  GTEST_SKIP() << "3MF reading is not compiled in (lamina_core built without zlib: needs "              \
                  "find_package(ZLIB), ZLIB::ZLIB and LAMINA_HAVE_ZLIB=1 in core/CMakeLists.txt)"

TEST(ThreeMf, WithoutZlibIsUnsupported) {
  if (three_mf_compiled()) GTEST_SKIP() << "3MF reading is compiled in";
  TempDir dir;
  auto r = read_mesh_file(dir.write("part.3mf", package(model(kTriangleObject, "<item objectid=\"1\"/>\n"))));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::unsupported);
  EXPECT_NE(r.error().message.find("3MF is not supported yet"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("part.3mf"), std::string::npos) << r.error().message;
}

TEST(ThreeMf, ReadsAMeshObjectExactly) {
  SKIP_WITHOUT_3MF();
  const std::string tetra =
      "<object id=\"7\" type=\"model\">\n<mesh>\n<vertices>\n"
      "<vertex x=\"0\" y=\"0\" z=\"0\" />\n<vertex x=\"10.5\" y=\"0\" z=\"0\" />\n"
      "<vertex x=\"0\" y=\"-2.25\" z=\"0\" />\n<vertex x=\"1e-3\" y=\"0\" z=\"3\" />\n</vertices>\n<triangles>\n"
      "<triangle v1=\"0\" v2=\"2\" v3=\"1\" />\n<triangle v1=\"0\" v2=\"1\" v3=\"3\" />\n"
      "<triangle v1=\"1\" v2=\"2\" v3=\"3\" pid=\"1\" p1=\"0\" />\n<triangle v1='2' v2='0' v3='3'/>\n"
      "</triangles>\n</mesh>\n</object>\n";
  auto soup = parse_3mf(package(model(tetra, "<item objectid=\"7\" />\n")), "tetra.3mf");
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "3mf");
  ASSERT_EQ(soup->triangle_count(), 4u);
  EXPECT_EQ(soup->corners[0], Eigen::Vector3f(0, 0, 0));
  EXPECT_EQ(soup->corners[1], Eigen::Vector3f(0, -2.25f, 0));
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(10.5f, 0, 0));
  EXPECT_EQ(soup->corners[5], Eigen::Vector3f(1e-3f, 0, 3));
  EXPECT_EQ(soup->corners[9], Eigen::Vector3f(0, -2.25f, 0));
  EXPECT_TRUE(soup->notes.empty());
}

TEST(ThreeMf, ComponentsAndBuildItemsComposeTransforms) {
  SKIP_WITHOUT_3MF();
  // Object 2 = object 1 moved by +10 x, plus object 1 turned 90° about z and lifted 5;
  // built once scaled by 2, and object 1 once as is.
  const std::string resources =
      kTriangleObject +
      "<object id=\"2\" type=\"model\"><components>\n"
      "<component objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 10 0 0\"/>\n"
      "<component objectid=\"1\" transform=\"0 1 0 -1 0 0 0 0 1 0 0 5\"/>\n"
      "</components></object>\n";
  const std::string build =
      "<item objectid=\"2\" transform=\"2 0 0 0 2 0 0 0 2 0 0 0\"/>\n<item objectid=\"1\"/>\n";
  auto soup = parse_3mf(package(model(resources, build)), "parts.3mf");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 3u);
  const Eigen::Vector3f expected[9] = {{20, 0, 0}, {22, 0, 0}, {20, 2, 0}, {0, 0, 10}, {0, 2, 10},
                                       {-2, 0, 10}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 9; ++i) EXPECT_EQ(soup->corners[i], expected[i]) << "corner " << i;
  EXPECT_TRUE(soup->notes.empty());

  // Items and components in other model parts (production extension) are skipped and noted.
  const std::string external = build + "<item objectid=\"4\" prod:path=\"/3D/other.model\"/>\n";
  auto partial = parse_3mf(package(model(resources, external)), "external.3mf");
  ASSERT_TRUE(partial) << partial.error().message;
  EXPECT_EQ(partial->triangle_count(), 3u);
  const ReadNote* note = find_note(*partial, "3mf_external_skipped");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("1 components or items"), std::string::npos) << note->message;
}

TEST(ThreeMf, DeflatedModelFoundThroughRelationships) {
  SKIP_WITHOUT_3MF();
  // Raw deflate (zlib level 9, wbits −15) of `xml` below, made with Python's zlib.
  const std::string xml = R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- deflated test model: a unit square (two triangles) at z = 7, unit inch -->
<model unit="inch" xml:lang="en-US" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">
 <resources>
  <object id="5" type="model">
   <mesh>
    <vertices>
     <vertex x="0" y="0" z="7"/>
     <vertex x="1" y="0" z="7"/>
     <vertex x="1" y="1" z="7"/>
     <vertex x="0" y="1" z="7"/>
    </vertices>
    <triangles>
     <triangle v1="0" v2="1" v3="2"/>
     <triangle v1="0" v2="2" v3="3"/>
    </triangles>
   </mesh>
  </object>
 </resources>
 <build>
  <item objectid="5"/>
 </build>
</model>
)";
  const std::string deflated(
      "\x8d\x90\xd1\x4e\xc2\x30\x14\x86\xef\x79\x8a\x63\xaf\x34\x71\x74\x1b\x21\x18\xd2\xc2\x9d\x2f\xa0"
      "\x3c\x40\xe9\x0e\xae\x66\x6d\xb1\xed\x26\xf0\xf4\x76\x1d\x13\x89\x98\x78\xb3\xac\xa7\x5f\xff\xf3"
      "\xe7\x63\xeb\x83\x6e\xa0\x43\xe7\x95\x35\x9c\x14\xd3\x9c\x00\x1a\x69\x2b\x65\xde\x38\xd9\xbc\x3e"
      "\x67\x4f\x64\xbd\x9a\xb0\xbb\x2c\x83\x0a\x77\x8d\x08\x58\x41\x40\x1f\x40\xdb\x0a\x9b\x25\x08\x68"
      "\x8d\x0a\xe0\x3f\x5a\xe1\x10\xee\xc3\xa7\x85\xe0\x94\x30\x6f\x0d\xfa\x07\x10\x01\x4e\xc0\x61\xf1"
      "\x38\x50\xca\xc8\x1a\xb2\x2c\xe6\xa5\xd7\x69\xc8\x49\x3f\x25\x10\x7b\x2c\x1b\xd1\x6f\x45\x93\x6d"
      "\x5e\xd2\xc0\x78\x4e\xea\x10\xf6\x4b\x4a\xbd\xac\x51\x0b\x3f\xd5\x4a\x3a\xeb\xed\x2e\x4c\xa5\xd5"
      "\x74\x56\x69\x61\xda\x9d\x90\xa1\x75\xb1\x31\x95\xd6\x21\x2d\xf3\x62\x4e\xf3\x92\xac\x26\xc0\x1c"
      "\x7a\xdb\x3a\x89\x3e\x1e\x80\xd9\xed\x3b\xca\x58\xa3\xe2\x64\x4e\x20\x1c\xf7\xc8\x49\x6a\xd2\xb3"
      "\xf1\x5e\xa3\xaf\xd3\x1f\xb0\xa8\x24\xa8\xf3\xbb\xf1\x8c\x07\x38\x70\x12\x0d\x1d\xd3\xf7\xc4\xc9"
      "\x82\xd0\xdf\x40\xf1\x3f\xa0\xf8\x1b\xc8\x6f\x01\x8c\x5e\x77\x62\xdf\x9e\xc7\x80\x71\x00\x5d\x91"
      "\x32\xba\x32\x85\x74\x33\x4e\xca\xcb\x9a\x5b\x54\x39\x50\xb3\xcb\xae\xeb\x70\x46\x47\x35\x8c\x0e"
      "\x12\x7b\xb9\xf4\xa7\x5d\xb6\x6d\x55\x53\x25\x44\x05\xd4\x30\x60\x83\x6a\x9a\xe8\x33\x10\xb3\x7a"
      "\xe5\xab\xc9\x17",
      316);
  ASSERT_EQ(xml.size(), 636u);
  ASSERT_EQ(test::crc32(xml), 0xf450915fu);
  const auto zip = make_zip({stored("[Content_Types].xml", kContentTypes), stored("_rels/.rels", rels("/3D/Other.model")),
                             ZipItem{"3D/other.model", deflated, 8, test::crc32(xml), 636}});
  TempDir dir;
  // Named .stl on purpose: a zip is tried as 3MF whatever its extension.
  auto soup = read_mesh_file(dir.write("square.stl", zip));
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "3mf");
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(1, 1, 7));
  EXPECT_EQ(soup->corners[5], Eigen::Vector3f(0, 1, 7));
  const ReadNote* units = find_note(*soup, "units");
  ASSERT_NE(units, nullptr);
  EXPECT_NE(units->message.find("'inch'"), std::string::npos) << units->message;

  // The same bytes with compressed bytes changed: an error, not garbage geometry.
  const std::string_view zip_text(reinterpret_cast<const char*>(zip.data()), zip.size());
  const std::size_t data_at = zip_text.find(deflated.substr(0, 16));
  ASSERT_NE(data_at, std::string_view::npos);
  for (std::size_t offset : {0u, 40u, 150u, 300u}) {
    auto corrupt = zip;
    corrupt[data_at + offset] ^= std::byte{0x5a};
    auto bad = parse_3mf(corrupt, "corrupt.3mf");
    ASSERT_FALSE(bad) << offset;
    EXPECT_EQ(bad.error().code, ErrorCode::parse_error) << bad.error().message;
    EXPECT_NE(bad.error().message.find("3D/other.model"), std::string::npos) << bad.error().message;
  }

  // A damaged relationships part is an error too (not a silent fall-back to the default path).
  auto bad_rels = zip;
  bad_rels[zip_text.find("Relationship Target") + 3] = std::byte{'#'};
  auto r = parse_3mf(bad_rels, "rels.3mf");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("'_rels/.rels' fails its CRC-32 check"), std::string::npos) << r.error().message;
}

TEST(ThreeMf, ReadsALib3mfPackageWithZip64Records) {
  SKIP_WITHOUT_3MF();
  auto soup = parse_3mf(test::as_bytes(kLib3mfCube), "cube.3mf");
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "3mf");
  ASSERT_EQ(soup->triangle_count(), 12u);
  EXPECT_NEAR(test::signed_volume(*soup), 10.0 * 20.0 * 30.0, 1e-6);
  Eigen::Vector3f lo = soup->corners[0], hi = soup->corners[0];
  for (const auto& c : soup->corners) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  EXPECT_EQ(lo, Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(hi, Eigen::Vector3f(11, 22, 33));
  EXPECT_TRUE(soup->notes.empty());
}

void expect_3mf_error(const std::vector<std::byte>& zip, ErrorCode code, std::string_view what) {
  auto r = parse_3mf(zip, "bad.3mf");
  ASSERT_FALSE(r) << "read " << r->triangle_count() << " triangles";
  EXPECT_EQ(r.error().code, code) << r.error().message;
  EXPECT_NE(r.error().message.find(what), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("bad.3mf"), std::string::npos) << r.error().message;
}

TEST(ThreeMf, ModelErrorsNameTheLine) {
  SKIP_WITHOUT_3MF();
  const std::string bad_index =
      "<object id=\"1\"><mesh><vertices>\n<vertex x=\"0\" y=\"0\" z=\"0\"/>\n</vertices><triangles>\n"
      "<triangle v1=\"0\" v2=\"0\" v3=\"1\"/>\n</triangles></mesh></object>\n";
  expect_3mf_error(package(model(bad_index, "<item objectid=\"1\"/>\n")), ErrorCode::parse_error,
                   "line 7: triangle vertex index 1 is out of range (object 1 has 1 vertices)");
  const std::string bad_number =
      "<object id=\"1\"><mesh><vertices>\n<vertex x=\"0\" y=\"zero\" z=\"0\"/>\n</vertices></mesh></object>\n";
  expect_3mf_error(package(model(bad_number, "")), ErrorCode::parse_error,
                   "line 5: <vertex> needs a number attribute 'y'");
  expect_3mf_error(package(model(kTriangleObject, "<item objectid=\"9\"/>\n")), ErrorCode::parse_error,
                   "line 9: object 9 does not exist");
  const std::string cycle = "<object id=\"3\"><components><component objectid=\"3\"/></components></object>\n";
  expect_3mf_error(package(model(cycle, "<item objectid=\"3\"/>\n")), ErrorCode::parse_error, "a cycle?");
  expect_3mf_error(package(model(kTriangleObject + kTriangleObject, "")), ErrorCode::parse_error,
                   "duplicate object id 1");
  expect_3mf_error(package(model(kTriangleObject, "<item objectid=\"1\" transform=\"1 0 0\"/>\n")),
                   ErrorCode::parse_error, "malformed transform");
  expect_3mf_error(package(model(kTriangleObject, "")), ErrorCode::empty_mesh, "no triangles");
  expect_3mf_error(package("<model><resources><object id=\"1\"><mesh><vertices><vertex x=\"1\""), ErrorCode::parse_error,
                   "unterminated XML markup");
}

TEST(ThreeMf, ContainerErrors) {
  SKIP_WITHOUT_3MF();
  const auto good = package(model(kTriangleObject, "<item objectid=\"1\"/>\n"));
  ASSERT_TRUE(parse_3mf(good, "good.3mf"));

  expect_3mf_error(make_zip({stored("3D/elsewhere.model", model(kTriangleObject, ""))}), ErrorCode::unknown_format,
                   "no model part '3D/3dmodel.model'");
  expect_3mf_error(std::vector<std::byte>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(good.size() - 30)),
                   ErrorCode::unknown_format, "not a zip archive");

  // A flipped byte inside the stored model: the CRC catches it.
  auto flipped = good;
  const std::string_view text(reinterpret_cast<const char*>(good.data()), good.size());
  flipped[text.find("<vertex x=\"1\"") + 10] = std::byte{'7'};
  expect_3mf_error(flipped, ErrorCode::parse_error, "CRC-32");

  // The central directory says the model is longer than the file.
  auto cut = good;
  cut.resize(text.find("[Content_Types].xml", text.find("PK\x01\x02")));  // keep local entries only
  expect_3mf_error(cut, ErrorCode::unknown_format, "no central directory");
}

TEST(ThreeMf, RandomAndMutatedPackagesNeverCrash) {
  SKIP_WITHOUT_3MF();
  const auto small = package(model(kTriangleObject, "<item objectid=\"1\"/>\n"));
  const auto cube = test::as_bytes(kLib3mfCube);
  const std::vector<std::byte> lib3mf(cube.begin(), cube.end());
  std::mt19937 rng(99);
  for (const auto& [good, triangles] : {std::pair{small, 1u}, std::pair{lib3mf, 12u}}) {
    int errors = 0;
    for (int round = 0; round < 3000; ++round) {
      auto bytes = good;
      for (int k = 1 + static_cast<int>(rng() % 4); k > 0; --k)
        bytes[rng() % bytes.size()] = static_cast<std::byte>(rng());
      if (round % 3 == 0) bytes.resize(rng() % bytes.size());
      auto r = parse_3mf(bytes, "m.3mf");
      if (!r) {
        ++errors;
      } else {
        EXPECT_EQ(r->triangle_count(), triangles);  // a change the CRC does not cover (a header field) may pass
      }
    }
    EXPECT_GT(errors, 1500) << triangles;
  }
}

}  // namespace
}  // namespace lamina
