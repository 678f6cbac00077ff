#include "common/gltf/compression.h"

#include <algorithm>
#include <memory>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>

#include "common/error.h"

namespace rastray {

std::vector<uint8_t> decodeMeshoptView(const MeshoptView& view, const uint8_t* source, size_t sourceBytes,
                                       const std::string& file, const std::string& element) {
  const size_t stride = view.byteStride;
  // check.cpp validated these; the decoders assert on them, so they are
  // restated here rather than trusted across files.
  const bool attributes = view.mode == MeshoptView::Mode::Attributes;
  if (attributes ? (stride == 0 || stride > 256 || stride % 4 != 0) : (stride != 2 && stride != 4))
    throw InputError(file, element,
                     "meshopt byteStride " + std::to_string(stride) + " is not valid for its mode");
  if (view.mode == MeshoptView::Mode::Triangles && view.count % 3 != 0)
    throw InputError(file, element,
                     "meshopt TRIANGLES count " + std::to_string(view.count) + " is not a multiple of 3");
  std::vector<uint8_t> out(view.count * stride);
  int status = 0;
  switch (view.mode) {
    case MeshoptView::Mode::Attributes:
      status = meshopt_decodeVertexBuffer(out.data(), view.count, stride, source, sourceBytes);
      break;
    case MeshoptView::Mode::Triangles:
      status = meshopt_decodeIndexBuffer(out.data(), view.count, stride, source, sourceBytes);
      break;
    case MeshoptView::Mode::Indices:
      status = meshopt_decodeIndexSequence(out.data(), view.count, stride, source, sourceBytes);
      break;
  }
  // meshoptimizer returns -1 for an unknown version or header, -2 for a
  // stream that ends early or does not fill exactly `count` elements.
  if (status != 0)
    throw InputError(file, element,
                     "meshopt " +
                         std::string(attributes                                  ? "vertex"
                                     : view.mode == MeshoptView::Mode::Triangles ? "triangle"
                                                                                 : "index") +
                         " stream does not decode (" +
                         (status == -1 ? "unsupported version or bad header" : "corrupt or truncated data") +
                         ", " + std::to_string(sourceBytes) + " bytes for " + std::to_string(view.count) +
                         " elements of " + std::to_string(stride) + " bytes)");
  // Filters work in place on the decoded elements (EXT_meshopt_compression,
  // "Filters"); the stride each needs was checked with the mode.
  const auto needStride = [&](bool ok, const char* filter) {
    if (!ok)
      throw InputError(
          file, element,
          std::string("meshopt filter ") + filter + " cannot use byteStride " + std::to_string(stride));
  };
  switch (view.filter) {
    case MeshoptView::Filter::None:
      break;
    case MeshoptView::Filter::Octahedral:
      needStride(attributes && (stride == 4 || stride == 8), "OCTAHEDRAL");
      meshopt_decodeFilterOct(out.data(), view.count, stride);
      break;
    case MeshoptView::Filter::Quaternion:
      needStride(attributes && stride == 8, "QUATERNION");
      meshopt_decodeFilterQuat(out.data(), view.count, stride);
      break;
    case MeshoptView::Filter::Exponential:
      needStride(attributes && stride % 4 == 0, "EXPONENTIAL");
      meshopt_decodeFilterExp(out.data(), view.count, stride);
      break;
  }
  return out;
}

namespace {

// The largest value of an accessor's integer component type, which
// normalisation divides by (glTF 2.0 §3.11); 0 for FLOAT.
double normalizationScale(int64_t componentType) {
  switch (componentType) {
    case 5120:
      return 127.0;
    case 5121:
      return 255.0;
    case 5122:
      return 32767.0;
    case 5123:
      return 65535.0;
    case 5125:
      return 4294967295.0;
    default:
      return 0.0;
  }
}

}  // namespace

DracoPrimitive decodeDracoPrimitive(const uint8_t* bytes, size_t size,
                                    const std::map<std::string, DracoAttributeRequest>& requests,
                                    const std::string& file, const std::string& element) {
  const std::string e = element + " KHR_draco_mesh_compression";
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes), size);
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok())
    throw InputError(file, e, "Draco stream does not decode: " + type.status().error_msg_string());
  if (type.value() != draco::TRIANGULAR_MESH)
    throw InputError(file, e, "Draco stream holds a point cloud, not a triangle mesh");
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    throw InputError(file, e, "Draco stream does not decode: " + decoded.status().error_msg_string());
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();

  DracoPrimitive out;
  out.points = mesh->num_points();
  out.indices.reserve(size_t(mesh->num_faces()) * 3);
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t p = mesh->face(f)[k].value();
      if (p >= out.points)
        throw InputError(file, e,
                         "Draco face " + std::to_string(f.value()) + " names point " + std::to_string(p) +
                             " (" + std::to_string(out.points) + " points)");
      out.indices.push_back(p);
    }

  for (const auto& [name, request] : requests) {
    const draco::PointAttribute* a = request.uniqueId <= int64_t(UINT32_MAX)
                                         ? mesh->GetAttributeByUniqueId(uint32_t(request.uniqueId))
                                         : nullptr;
    if (!a)
      throw InputError(
          file, e,
          "attribute " + name + ": the Draco stream has no attribute " + std::to_string(request.uniqueId));
    const size_t n = a->num_components();
    if (n < 1 || n > 4)
      throw InputError(file, e,
                       "attribute " + name + " has " + std::to_string(n) + " components in the Draco stream");
    // An integer attribute the accessor calls normalized but Draco does not
    // (Draco normalises itself when its own flag is set).
    const bool integer = a->data_type() != draco::DT_FLOAT32 && a->data_type() != draco::DT_FLOAT64;
    const double scale =
        request.normalized && integer && !a->normalized() ? normalizationScale(request.componentType) : 0.0;
    DracoAttribute& d = out.attributes[name];
    d.components = n;
    d.values.resize(out.points * n);
    for (uint32_t p = 0; p < out.points; ++p) {
      const draco::AttributeValueIndex v = a->mapped_index(draco::PointIndex(p));
      if (!(v.value() < a->size()))
        throw InputError(file, e,
                         "attribute " + name + ": point " + std::to_string(p) + " maps to value " +
                             std::to_string(v.value()) + " (" + std::to_string(a->size()) + " values)");
      double* dst = d.values.data() + size_t(p) * n;
      if (!a->ConvertValue<double>(v, int8_t(n), dst))
        throw InputError(file, e,
                         "attribute " + name + ": value " + std::to_string(v.value()) + " does not convert");
      if (scale > 0.0)
        for (size_t k = 0; k < n; ++k) dst[k] = std::max(dst[k] / scale, -1.0);
    }
  }
  return out;
}

}  // namespace rastray
