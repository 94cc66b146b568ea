# The NEON check (neon_check.cpp) with the kernels it holds to the reference,
# built for aarch64 into the current directory; scripts/check-neon.sh runs
#     make -C build/neon-check -f <repo>/cpp/check/neon_check.mk ROOT=<repo> CXX=<compiler>
# Incremental: each object is rebuilt when its source or a header it includes changes.
ROOT ?= $(abspath $(dir $(lastword $(MAKEFILE_LIST)))/../..)
ifeq ($(origin CXX),default)
CXX := aarch64-linux-gnu-g++
endif
MAKEFLAGS += --no-builtin-rules

# CMakeLists.txt's principled_brdf_kernels library on aarch64: the baseline
# sources and the NEON kernel, this one with the kernels' flags.
LIBRARY := batch dispatch energy_corners energy_intercepts energy_tables thread_pool
CXXFLAGS := -std=c++17 -O2 -DNDEBUG -Wno-psabi -I$(ROOT)/cpp/include -I$(ROOT)/cpp/src -isystem /usr/include/eigen3 \
            -DPRINCIPLED_BRDF_HAVE_NEON
KERNEL_FLAGS := -ffp-contract=off -fno-math-errno
OBJECTS := $(LIBRARY:%=%.o) kernel_neon.o neon_check.o

neon_check: $(OBJECTS)
	$(CXX) -static -pthread -o $@ $^

kernel_neon.o: CXXFLAGS += $(KERNEL_FLAGS)
# the float64 reference rounded as written, as on x86-64 (GCC contracts a b + c
# into fused multiply-adds by default on AArch64)
neon_check.o: CXXFLAGS += -ffp-contract=off

%.o: $(ROOT)/cpp/src/%.cpp
	$(CXX) $(CXXFLAGS) -MMD -MP -c $< -o $@

neon_check.o: $(ROOT)/cpp/check/neon_check.cpp
	$(CXX) $(CXXFLAGS) -MMD -MP -c $< -o $@

# (a changed compiler or flag: delete the build folder)
-include $(OBJECTS:.o=.d)
