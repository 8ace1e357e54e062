# What the Python face (python/) needs: pybind11 and a Python 3 interpreter with its headers and
# numpy. Sets CHEVAL_PYTHON_AVAILABLE (the default of CHEVAL_BUILD_PYTHON) and, when found,
# Python3_EXECUTABLE, which the module is built for and its tests run with.
#
# The interpreter must import numpy: the module hands out numpy arrays. -DPython3_EXECUTABLE=...
# wins; otherwise the first of `python3` on PATH and /usr/bin/python3 (Debian's, which
# python3-numpy, python3-dev and pybind11-dev serve) that imports numpy is taken, so a pyenv or venv
# python3 without numpy earlier on PATH does not hide Debian's.
set(CHEVAL_PYTHON_AVAILABLE OFF)
if(CHEVAL_SANITIZE OR CHEVAL_BUILD_FUZZERS)
  return()  # an instrumented module needs the sanitizer runtime preloaded into Python
endif()

if(NOT Python3_EXECUTABLE)
  find_program(CHEVAL_PATH_PYTHON3 NAMES python3 NO_CACHE)
  foreach(candidate IN ITEMS ${CHEVAL_PATH_PYTHON3} /usr/bin/python3)
    if(EXISTS "${candidate}")
      execute_process(COMMAND "${candidate}" -c "import numpy" RESULT_VARIABLE status OUTPUT_QUIET ERROR_QUIET)
      if(status EQUAL 0)
        set(Python3_EXECUTABLE "${candidate}" CACHE FILEPATH "Python 3 interpreter (with numpy) of the Python module")
        break()
      endif()
    endif()
  endforeach()
  if(NOT Python3_EXECUTABLE)
    message(STATUS "cheval: no python3 with numpy found (apt-get install python3-numpy): Python module off")
    return()
  endif()
endif()

find_package(Python3 COMPONENTS Interpreter Development.Module QUIET)
if(Python3_FOUND)
  find_package(pybind11 2.6 CONFIG QUIET)  # after Python3: pybind11 then uses FindPython's interpreter
endif()
if(Python3_FOUND AND pybind11_FOUND)
  set(CHEVAL_PYTHON_AVAILABLE ON)
  message(STATUS "cheval: Python module for ${Python3_EXECUTABLE} (${Python3_VERSION}), pybind11 ${pybind11_VERSION}")
else()
  message(STATUS "cheval: pybind11 or the Python headers not found (apt-get install pybind11-dev python3-dev): "
                 "Python module off")
endif()
