# The sources SPHERA builds on, pinned. Plain variables, no side effects, so
# that a test can include this file with `cmake -P` and compare the pins with
# the COLMAP source.
#
# Upstream COLMAP at this commit (4.2.0.dev0, 2026-08-08) is the base of the
# patch series; its commit id authenticates a git checkout.
set(SPHERA_COLMAP_PINNED_COMMIT "5d968cf38aa2574fd284b0dc86c3d58d124940b3")
set(SPHERA_COLMAP_PINNED_GIT_URL "https://github.com/colmap/colmap.git")

# PoseLib and faiss exactly as that commit pins them
# (src/thirdparty/CMakeLists.txt: FetchContent_Declare URL and URL_HASH).
set(SPHERA_POSELIB_PINNED_URL
    "https://github.com/PoseLib/PoseLib/archive/fa7280fee27f97aff31ae7f98bab7f583fac7d08.zip")
set(SPHERA_POSELIB_PINNED_SHA256
    "5408d4ae8ce367cb2f076bc6c5f0f6f78abd3573d2c015304b04e46f23455f5b")
set(SPHERA_FAISS_PINNED_URL
    "https://github.com/facebookresearch/faiss/archive/refs/tags/v1.14.1.zip")
set(SPHERA_FAISS_PINNED_SHA256
    "4b1ae7e7a0a46385b4084f0e3945623a15fcf99d793bf44d82aae8e24f11e5f5")

# The offline snapshot: tarballs of the same COLMAP commit, of PoseLib at
# a69263d with a stand-in for relpose_6pt_onesided_focal (it returns no
# solutions) and of faiss 1.14.1.
set(SPHERA_COLMAP_NAME "colmap-5d968cf")
set(SPHERA_COLMAP_SHA256
    "1c6c1a735774d8bc442900d52aac5359dcc9c7ffe53d3daba054fa3095de8dc1")
set(SPHERA_POSELIB_NAME "PoseLib-a69263d")
set(SPHERA_POSELIB_SHA256
    "7b8d9b0aae73feeb7ba202261e1ff90dd7d166316b263210b6f9456303722e2d")
set(SPHERA_FAISS_NAME "faiss-1.14.1")
set(SPHERA_FAISS_SHA256
    "0216d38d8c5c460433815b72d3cde6725eaa5d5770576277a2abc01ffc414d20")
