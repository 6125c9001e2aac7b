# The ROS wheels were built on manylinux: the <pkg>::<pkg>__rosidl_generator_py targets they
# export name that image's Python (/opt/python/...) as their include directories, which do
# not exist here. Point every such imported target of this directory at the Python and
# NumPy headers of the interpreter we build for (Python3_EXECUTABLE).
find_package(Python3 REQUIRED COMPONENTS Interpreter Development.Module NumPy)
get_property(_openral_imported DIRECTORY PROPERTY IMPORTED_TARGETS)
foreach(_target IN LISTS _openral_imported)
  if(_target MATCHES "__rosidl_generator_py$")
    set_target_properties(${_target} PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${Python3_INCLUDE_DIRS};${Python3_NumPy_INCLUDE_DIRS}")
  endif()
endforeach()
