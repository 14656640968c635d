// tinygltf_read.h — the glTF tests' second reader: an exported file loaded with Debian's
// tinygltf 2.7 (never sylva's own reader), and its accessors as plain values.
#pragma once

#include <gtest/gtest.h>
#include <tiny_gltf.h>  // declarations only; the implementation is Debian's shared library

#include <cstring>
#include <string>
#include <vector>

namespace sylva::test {

// Loads `path` (.glb or .gltf); a test failure with tinygltf's error or warning otherwise.
inline bool load_with_tinygltf(const std::string& path, tinygltf::Model* model) {
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool ok = path.ends_with(".glb") ? loader.LoadBinaryFromFile(model, &err, &warn, path)
                                         : loader.LoadASCIIFromFile(model, &err, &warn, path);
  EXPECT_TRUE(ok) << err;
  EXPECT_TRUE(warn.empty()) << warn;
  return ok;
}

// The components of accessor `index` (tightly packed, as sylva writes them), of
// component type `component` (TINYGLTF_COMPONENT_TYPE_*) stored as T.
template <class T>
std::vector<T> components_of(const tinygltf::Model& model, int index, int component) {
  const tinygltf::Accessor& a = model.accessors.at(static_cast<size_t>(index));
  EXPECT_EQ(a.componentType, component);
  const tinygltf::BufferView& view = model.bufferViews.at(static_cast<size_t>(a.bufferView));
  const std::vector<unsigned char>& data = model.buffers.at(static_cast<size_t>(view.buffer)).data;
  const size_t n = a.count * static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type)));
  std::vector<T> out(n);
  EXPECT_LE(view.byteOffset + a.byteOffset + n * sizeof(T), data.size());
  std::memcpy(out.data(), data.data() + view.byteOffset + a.byteOffset, n * sizeof(T));
  return out;
}

// A float accessor's components.
inline std::vector<float> floats_of(const tinygltf::Model& model, int index) {
  return components_of<float>(model, index, TINYGLTF_COMPONENT_TYPE_FLOAT);
}

// An unsigned short accessor's components (JOINTS_0 as sylva writes it).
inline std::vector<uint16_t> u16s_of(const tinygltf::Model& model, int index) {
  return components_of<uint16_t>(model, index, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
}

}  // namespace sylva::test
