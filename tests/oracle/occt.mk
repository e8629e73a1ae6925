# OpenCASCADE oracle of the CAD writers (included by the main Makefile; B = build dir).
# tests/oracle/occt_read.cpp is test-only C++ against Debian's OpenCASCADE 7.6
# (libocct-data-exchange-dev pulls the modelling and foundation libraries it links).
# Until the Makefile compiles csrc/*/*.c itself, the CAD writers in csrc/io/ are added to the
# library sources here (only those not already listed, so nothing is compiled twice).
# .DEFAULT_GOAL is saved/restored so this fragment does not become the default goal.
OCCT_SAVED_GOAL := $(.DEFAULT_GOAL)
APT_PKGS += libocct-data-exchange-dev
CAD_SRC  := $(filter-out $(LIB_SRC),$(sort $(wildcard csrc/io/*.c)))
LIB_SRC  += $(CAD_SRC)
HDRS     += $(if $(CAD_SRC),$(wildcard csrc/io/*.h))
OCCT_INC  = -I/usr/include/opencascade
OCCT_LIBS = -lTKSTEP -lTKSTEPBase -lTKIGES -lTKXSBase -lTKShHealing -lTKTopAlgo -lTKGeomAlgo -lTKBRep \
            -lTKGeomBase -lTKG3d -lTKG2d -lTKMath -lTKernel

$(B)/occt_read: tests/oracle/occt_read.cpp
	@mkdir -p $(@D)
	$(CXX) -std=c++14 -O1 -Wall -Wextra -Werror $(OCCT_INC) $< -o $@ $(OCCT_LIBS)

# Prototype of the unpacked export (tests/oracle/EXPORT_DESIGN.md): plan patches -> CAD faces.
$(B)/cad_from_patches: tests/oracle/cad_from_patches.c tests/oracle/cad_pack.h $(B)/libccnurbs.a $(HDRS)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) -Icsrc $(WARN) $(CFLAGS) $< -o $@ $(B)/libccnurbs.a $(LDLIBS)

TEST_DEPS += $(B)/occt_read $(B)/cad_from_patches
.DEFAULT_GOAL := $(OCCT_SAVED_GOAL)
