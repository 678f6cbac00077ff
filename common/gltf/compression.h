// Decoders for glTF's compressed geometry (scene_builder.cpp calls them):
// KHR_draco_mesh_compression through libdraco, EXT_meshopt_compression and
// KHR_meshopt_compression through libmeshoptimizer.
//
// Both take bytes whose ranges check.cpp proved inside their buffers and
// parameters check.cpp validated (strides, modes, filters), and throw
// InputError naming the file and the element for every stream that does
// not decode to exactly what the JSON declares. What they return is raw
// decoded data: the scene builder puts it through the same checks as
// plain accessors (counts, index ranges, NaN/Inf).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rastray {

// One EXT_/KHR_meshopt_compression bufferView (the extension's fields).
struct MeshoptView {
  enum class Mode { Attributes, Triangles, Indices };
  enum class Filter { None, Octahedral, Quaternion, Exponential };
  Mode mode = Mode::Attributes;
  Filter filter = Filter::None;
  size_t count = 0;       // elements (vertices or indices)
  size_t byteStride = 0;  // bytes per element once decoded
};

// Decodes `source` (the compressed bytes) into count × byteStride bytes,
// the bufferView's content, filters applied in place. `element` names the
// bufferView in messages ("bufferView 3").
std::vector<uint8_t> decodeMeshoptView(const MeshoptView& view, const uint8_t* source, size_t sourceBytes,
                                       const std::string& file, const std::string& element);

// One decoded Draco attribute: `components` values per point, point by
// point (Draco's attribute values gathered through its point → value map),
// as doubles. Integer attributes the accessor declares normalized are
// normalised by the accessor's component type (glTF 2.0 §3.11), as plain
// accessors are; Draco's dequantisation of positions and normals is done
// in float by libdraco.
struct DracoAttribute {
  size_t components = 0;
  std::vector<double> values;
};

struct DracoPrimitive {
  size_t points = 0;                                 // vertices after decoding
  std::vector<uint32_t> indices;                     // three per face, each < points
  std::map<std::string, DracoAttribute> attributes;  // by glTF attribute name
};

// What the scene builder asks of one Draco attribute: its unique id in the
// stream and how the accessor describes it.
struct DracoAttributeRequest {
  int64_t uniqueId = 0;
  int64_t componentType = 5126;  // the accessor's
  bool normalized = false;       // the accessor's
};

// Decodes a Draco triangle mesh and the requested attributes. `element`
// names the primitive ("mesh 2 primitive 0"). Refuses point clouds,
// undecodable streams, attribute ids the stream does not hold and face
// indices beyond the decoded points.
DracoPrimitive decodeDracoPrimitive(const uint8_t* bytes, size_t size,
                                    const std::map<std::string, DracoAttributeRequest>& requests,
                                    const std::string& file, const std::string& element);

}  // namespace rastray
