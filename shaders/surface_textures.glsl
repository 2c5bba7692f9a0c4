// Surface textures (render.comp): the albedo textures of textured shapes,
// read by the surface vertex (vertex.glsl).

// A surface's albedo texture (Shape.texture; binding BINDING_TEXTURES in
// render_bindings.glsl) at uv. Texture arrays are indexed with constants only,
// and with at most one texture the switch's other lookups compile out
// (docs/rendering.md "llvmpipe workarounds": every branch runs).
vec3 albedo_texture_at(uint slot, vec2 uv) {
  if (ALBEDO_TEXTURE_COUNT <= 1u) return textureLod(albedo_tex[0], uv, 0.0).rgb;
  switch (slot) {
    case 0u: return textureLod(albedo_tex[0], uv, 0.0).rgb;
    case 1u: return textureLod(albedo_tex[1], uv, 0.0).rgb;
    case 2u: return textureLod(albedo_tex[2], uv, 0.0).rgb;
    case 3u: return textureLod(albedo_tex[3], uv, 0.0).rgb;
    case 4u: return textureLod(albedo_tex[4], uv, 0.0).rgb;
    case 5u: return textureLod(albedo_tex[5], uv, 0.0).rgb;
    case 6u: return textureLod(albedo_tex[6], uv, 0.0).rgb;
    default: return textureLod(albedo_tex[7], uv, 0.0).rgb;
  }
}
