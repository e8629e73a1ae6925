# OpenCASCADE oracle of the CAD writers (included by the main Makefile; B = build dir).
# tests/oracle/occt_read.cpp is test-only C++ against Debian's OpenCASCADE 7.6
# (libocct-data-exchange-dev pulls the modelling and foundation libraries it links).
# .DEFAULT_GOAL is saved/restored so this fragment does not become the default goal.
OCCT_SAVED_GOAL := $(.DEFAULT_GOAL)
APT_PKGS += libocct-data-exchange-dev
OCCT_INC  = -I/usr/include/opencascade
OCCT_LIBS = -lTKSTEP -lTKSTEPBase -lTKIGES -lTKXSBase -lTKShHealing -lTKTopAlgo -lTKGeomAlgo -lTKBRep \
            -lTKGeomBase -lTKG3d -lTKG2d -lTKMath -lTKernel

$(B)/occt_read: tests/oracle/occt_read.cpp
	@mkdir -p $(@D)
	$(CXX) -std=c++14 -O1 -Wall -Wextra -Werror $(OCCT_INC) $< -o $@ $(OCCT_LIBS)

TEST_DEPS += $(B)/occt_read
.DEFAULT_GOAL := $(OCCT_SAVED_GOAL)
