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
# sources and the NEON kernel, this one with the kernels' flags and in the
# parts CMakeLists.txt compiles it in (one per PB_KERNEL_PART_ of
# cpp/src/kernel_parts.hpp), so that `make -j2` keeps two cores busy.
LIBRARY := batch dielectric_energy_tables dispatch energy_corners energy_intercepts energy_tables thread_pool
CXXFLAGS := -std=c++17 -O2 -DNDEBUG -Wno-psabi -I$(ROOT)/cpp/include -I$(ROOT)/cpp/src -isystem /usr/include/eigen3 \
            -DPRINCIPLED_BRDF_HAVE_NEON
KERNEL_FLAGS := -ffp-contract=off -fno-math-errno \
                --param=sccvn-max-alias-queries-per-access=100 --param=dse-max-alias-queries-per-store=32
# the parts' numbers in CMakeLists.txt's kernel_parts_longest_first order, the order make starts them in
KERNEL_PARTS := $(shell awk '/^set\(kernel_parts / { for (i = 2; i <= NF; i++) { sub(/\)/, "", $$i); number[$$i] = i - 1 } } \
                             /^set\(kernel_parts_longest_first / { for (i = 2; i <= NF; i++) { sub(/\)/, "", $$i); print number[$$i] } }' \
                        $(ROOT)/CMakeLists.txt)
KERNEL_OBJECTS := $(KERNEL_PARTS:%=kernel_neon_part%.o)
OBJECTS := $(LIBRARY:%=%.o) $(KERNEL_OBJECTS) neon_check.o

neon_check: $(OBJECTS)
	$(CXX) -static -pthread -o $@ $^

kernel_neon_part%.o: $(ROOT)/cpp/src/kernel_neon.cpp
	$(CXX) $(CXXFLAGS) $(KERNEL_FLAGS) -DPRINCIPLED_BRDF_KERNEL_PART=$* -MMD -MP -c $< -o $@
# the float64 reference rounded as written, as on x86-64 (GCC contracts a b + c
# into fused multiply-adds by default on AArch64)
neon_check.o: CXXFLAGS += -ffp-contract=off

%.o: $(ROOT)/cpp/src/%.cpp
	$(CXX) $(CXXFLAGS) -MMD -MP -c $< -o $@

neon_check.o: $(ROOT)/cpp/check/neon_check.cpp
	$(CXX) $(CXXFLAGS) -MMD -MP -c $< -o $@

# (a changed compiler or flag: delete the build folder)
-include $(OBJECTS:.o=.d)
