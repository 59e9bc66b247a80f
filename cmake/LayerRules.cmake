# The layers (docs/ARCHITECTURE.md) as rules the build keeps: what each library may link,
# directly or through the libraries it links, and what its sources may include. Checked once
# every target is defined; a broken rule fails the configure step, naming the path that breaks it.
#
#   terralux_bake (renderer/ less vk/ and render/): the CPU bake; no Qt, no Vulkan
#   terralux_io: file formats; no Qt, no Vulkan
#   terralux_core: project, parameters, bake jobs, command line (terralux-bake); Qt Core only
#   terralux_vulkan, terralux_app: the device renderer and the jobs that draw
#   terralux_ui: the authoring window
# Unit tests link terralux_core (no Vulkan); a test that needs the device says so with the
# target property TERRALUX_NEEDS_DEVICE.

# Every library `target` links, following our own libraries (terralux_*) through their link
# interfaces; "a -> b -> c" paths in `out_paths`, the names in `out`.
function(terralux_link_closure target out out_paths)
  set(seen "")
  set(paths "")
  set(queue "${target}")
  set(via_${target} "${target}")
  while(queue)
    list(POP_FRONT queue t)
    if(t IN_LIST seen)
      continue()
    endif()
    list(APPEND seen "${t}")
    if(NOT TARGET "${t}" OR NOT t MATCHES "^(terralux_|test_)")
      continue()
    endif()
    get_target_property(type "${t}" TYPE)
    set(links "")
    if(NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(direct "${t}" LINK_LIBRARIES)
      if(direct)
        list(APPEND links ${direct})
      endif()
    endif()
    get_target_property(interface "${t}" INTERFACE_LINK_LIBRARIES)
    if(interface)
      list(APPEND links ${interface})
    endif()
    foreach(l IN LISTS links)
      string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" l "${l}")
      if(l MATCHES "^\\$<" OR l IN_LIST seen)
        continue()
      endif()
      if(NOT DEFINED via_${l})
        set(via_${l} "${via_${t}} -> ${l}")
      endif()
      list(APPEND queue "${l}")
    endforeach()
  endwhile()
  foreach(s IN LISTS seen)
    list(APPEND paths "${via_${s}}")
  endforeach()
  set(${out} "${seen}" PARENT_SCOPE)
  set(${out_paths} "${paths}" PARENT_SCOPE)
endfunction()

# Fails when `target` links any library matching `pattern` (a regex).
function(terralux_forbid_link target pattern why)
  terralux_link_closure(${target} names paths)
  foreach(p IN LISTS paths)
    string(REGEX REPLACE ".* -> " "" last "${p}")
    if(last MATCHES "${pattern}")
      message(FATAL_ERROR "layer rule: ${target} must not link ${last} (${why}); it does through ${p}")
    endif()
  endforeach()
endfunction()

# Fails when a source or header under `dir` includes a header matching `pattern`.
function(terralux_forbid_include dir pattern why)
  file(GLOB_RECURSE files "${dir}/*.h" "${dir}/*.cpp")
  foreach(f IN LISTS files)
    file(STRINGS "${f}" hits REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"](${pattern})")
    if(hits)
      list(GET hits 0 hit)
      string(REGEX REPLACE ".*[<\"]([^>\"]+)[>\"].*" "\\1" hit "${hit}")
      file(RELATIVE_PATH rel "${PROJECT_SOURCE_DIR}" "${f}")
      message(FATAL_ERROR "layer rule: ${rel} must not include ${hit} (${why})")
    endif()
  endforeach()
endfunction()

set(_no_device "^(Vulkan::Vulkan|terralux_vulkan|terralux_app|terralux_ui|terralux_shaders)$")
set(_no_qt "^Qt6::")
set(_no_qt_gui "^Qt6::(Gui|Widgets|Charts|OpenGL|OpenGLWidgets|Svg|Quick)$")
terralux_forbid_link(terralux_bake "${_no_device}" "the bake runs without a device")
terralux_forbid_link(terralux_bake "${_no_qt}" "the bake is plain C++")
terralux_forbid_link(terralux_io "${_no_device}" "file formats run without a device")
terralux_forbid_link(terralux_io "${_no_qt}" "file formats are plain C++")
terralux_forbid_link(terralux_core "${_no_device}" "terralux-bake runs without a device")
terralux_forbid_link(terralux_core "${_no_qt_gui}" "terralux-bake runs without a display")
foreach(dir bake lpv scene system terrain water)
  terralux_forbid_include("${PROJECT_SOURCE_DIR}/renderer/${dir}" "vulkan/|Q[A-Za-z]+|Qt" "renderer/${dir} is the CPU bake")
endforeach()
terralux_forbid_include("${PROJECT_SOURCE_DIR}/io" "vulkan/|Q[A-Za-z]+|Qt" "io/ is plain C++")

get_property(_unit_tests GLOBAL PROPERTY TERRALUX_UNIT_TESTS)
foreach(t IN LISTS _unit_tests)
  get_target_property(device ${t} TERRALUX_NEEDS_DEVICE)
  if(NOT device)
    terralux_forbid_link(${t} "${_no_device}" "a unit test of the bake; set TERRALUX_NEEDS_DEVICE if it draws")
  endif()
endforeach()
