#pragma once
// Internal to solver/io: the schemas/*.schema.json texts, compiled into the library by
// solver/io/embed_schemas.cmake (the generated source defines these).
#include <cstddef>

namespace grip::schema_io {

struct EmbeddedSchema {
  const char* stem;  // "scene" for schemas/scene.schema.json
  const char* text;
};

extern const EmbeddedSchema kEmbeddedSchemas[];
extern const std::size_t kEmbeddedSchemaCount;

}  // namespace grip::schema_io
