# Tests of the OpenGL pipeline; included from tests/render/CMakeLists.txt (after lucent_add_test is
# defined in tests/CMakeLists.txt). They skip themselves (GTEST_SKIP) where no headless OpenGL 4.5
# context can be made. Keep renders tiny: on llvmpipe they are ~1000x slower than on a GPU.
lucent_add_test(glsl_twin_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/glsl_twin_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(radiance_maps_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/radiance_maps_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(radiance_maps_sampling_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/radiance_maps_sampling_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(radiance_maps_split_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/radiance_maps_split_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(ground_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/ground_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(faceted_mesh_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/faceted_mesh_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(slab_truth_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/slab_truth_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(sh_renderer_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/sh_renderer_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(fur_renderer_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/fur_renderer_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(fur_coat_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/fur_coat_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(fur_glsl_twin_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/fur_glsl_twin_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(area_light_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/area_light_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(geometry_factor_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/geometry_factor_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(oblique_skew_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/oblique_skew_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
# White-box: both include private headers of render/ (gl_program.h, gl_bssrdf.h,
# radiance_maps_sampling.h).
foreach(t glsl_twin_test geometry_factor_test oblique_skew_test radiance_maps_test
          radiance_maps_sampling_test radiance_maps_split_test ground_test sh_renderer_test area_light_test fur_glsl_twin_test
          fur_renderer_test)
  target_include_directories(${t} PRIVATE ${LUCENT_RENDER_PRIVATE_DIRS})
endforeach()
lucent_add_test(single_scattering_gl_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/single_scattering_gl_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(hierarchical_renderer_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/hierarchical_renderer_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(tradeoff_bench_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/tradeoff_bench_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
lucent_add_test(technique_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/technique_test.cpp
  LIBS lucent::render lucent::materials OpenGL::OpenGL)
