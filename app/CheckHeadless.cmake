# cmake -DBINARY=terralux-bake -P CheckHeadless.cmake
# Fails when BINARY needs, directly or through any library it loads, a GUI toolkit module or the
# Vulkan loader: the headless bake must install on a farm node with no desktop and no GPU stack.
if(NOT BINARY)
  message(FATAL_ERROR "CheckHeadless.cmake: pass -DBINARY=FILE")
endif()
file(GET_RUNTIME_DEPENDENCIES
  EXECUTABLES "${BINARY}"
  RESOLVED_DEPENDENCIES_VAR resolved
  UNRESOLVED_DEPENDENCIES_VAR unresolved)
set(forbidden "libvulkan\\.so|libQt6(Gui|Widgets|Charts|OpenGL|OpenGLWidgets|Svg|Quick)\\.so")
set(found "")
foreach(lib ${resolved} ${unresolved})
  get_filename_component(name "${lib}" NAME)
  if(name MATCHES "${forbidden}")
    list(APPEND found "${name}")
  endif()
endforeach()
if(found)
  list(JOIN found ", " found)
  message(FATAL_ERROR "${BINARY}: the headless binary loads ${found}; it may link no GUI module and "
                      "no Vulkan loader (keep terralux_vulkan, terralux_ui and Qt6::Gui out of its targets)")
endif()
list(LENGTH resolved count)
message(STATUS "${BINARY}: headless (${count} libraries, none of them a GUI module or the Vulkan loader)")
