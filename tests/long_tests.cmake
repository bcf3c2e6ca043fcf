# The tests that take longest under the sanitizers, labelled `long`: the `asan` test preset
# (scripts/test.sh) leaves them out and `asan-long` (scripts/test.sh --long, also run by
# .ci/run) runs only them; the release suite runs them always (docs/testing.md). Read by ctest
# after the discovered GoogleTest tests (tests/CMakeLists.txt); ctest ignores a name that is not
# built here (no Embree, say).
set(AMALGAM_LONG_TESTS
  Experiments.AWrongFormulaTurnsTheVerdict
  BadInput.EveryTestModelImportsOrIsAnInputError
  Embree.ShadowRaysAgreeWhereBothHitTheSamePrimitive
  Volumetric.MeadowTilesWithin3PercentOfFullDetail
  ExperimentCli.OutWritesCsvPlotAndReportForEveryExperiment
  Experiments.EveryCheckBearsOnAListedStatement
  CliLimits.ProgressBarOnlyOnATerminal
  Embree.EveryExampleSceneMatchesTheTraditionalRenderer
  Volumetric.CorrelationFitGivesTheCoverage
  VolumeCells.CoverageAlongLinesMatchesTheHitProbability
  Experiments.ExpectedMatchesEq9AndRefutesPrintedEq12
  BiasReference.CompositeFootprint2IsWithin3PercentOfFullDetailPerTile
  StratifiedSampler.ConvergesFasterThanIndependentOnEdges
  Volumetric.CloseUpIsFullDetail
  Volumetric.SameBytesForAnyThreadCount
  Volumetric.CellTestsAddUp
  CliLimits.LoadPhasesShownOnATerminal
)
set_tests_properties(${AMALGAM_LONG_TESTS} PROPERTIES LABELS long)
