# A real one-node Slurm cluster started in the test machine (docs/scale.md): a 4-shard synth job
# array and its merge job through `mirage slurm`, checked bit for bit against one process.
# Skipped (exit 77, with the reason) where Slurm cannot start: not root, packages missing.
add_test(NAME slurm_cluster
         COMMAND bash ${CMAKE_CURRENT_LIST_DIR}/slurm_cluster_test.sh $<TARGET_FILE:mirage>
                 ${PROJECT_SOURCE_DIR}/data/scenes/tabletop/tabletop.gltf
                 ${CMAKE_CURRENT_BINARY_DIR}/output/slurm)
set_tests_properties(slurm_cluster PROPERTIES LABELS "cluster" TIMEOUT 600 SKIP_RETURN_CODE 77)
