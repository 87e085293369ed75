"""``faultgen bench-isolators``, ``detect``, ``training-source`` and ``classify``: the fault
detection and isolation methods of the ``analysis`` package run on a dataset."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from faultgen.bench import baselines
from faultgen.checks import MAX_SEED
from faultgen.cli.base import Command, check_outputs, parse_window
from faultgen.cli.main import app
from faultgen.data import atomic
from faultgen.data import cells as csv_cells
from faultgen.cli.options import (
    MAX_CYCLES, MAX_DAYS, MAX_FOLDS, MAX_PAIRS, MAX_PERMUTATIONS, MAX_SAMPLES, Overwrite, Progress, QAlpha,
)

#: ``--train OTHER.h5`` of every detector and isolator command (analysis.crossdata).
Train = Annotated[Path | None, typer.Option(
    "--train", metavar="OTHER.h5",
    help="Learn normal operation (or the classes) from this other dataset instead of FILE itself, e.g. simulated "
         "nominal data for an imported fleet's logs; its robots must have FILE's axes, ranges and limits. Each unit's "
         "features are centred and scaled by its own first records (thesis ch. 4); the output states the protocol "
         "(own history, another dataset, the twin).")]


def analysis_input(file: Path, outputs: list[Path], overwrite: bool) -> None:
    """Refuse a dataset that fails validation, or outputs that exist, before any analysis runs."""
    from faultgen.data import dataset, reader

    problems = dataset.validate(file)
    if problems:
        raise ValueError(f"{file} fails validation (run `faultgen validate {file}`): {problems[0]}")
    check_outputs(outputs, overwrite)
    with reader.open(file) as data:
        failing, unhashed = data.failing, data.unhashed
        imported = all(run.measured for run in data.runs)
    if unhashed:  # old files: runs are paired by their task label alone
        typer.echo(unhashed)
    if not failing and imported:
        from analysis import benchmark

        raise ValueError(f"{file} has no log labelled worn (its logs' events.csv has no `onset` or `failure` row): the "
                         f"analyses compare worn logs with healthy ones; {benchmark.MEASURED_NEXT}")
    if not failing:
        raise ValueError(f"{file} has no worn run (every run is without wear or fault): the analyses compare worn "
                         "runs with runs without wear; sweep with --axis 1..6 too")


def parse_levels(levels: str) -> list[float]:
    """``--levels``: wear levels in %, comma-separated, each within 0..500 %.

    Raises
    ------
    ValueError
        Naming the option's value and what was expected.
    """
    try:
        wear_levels = [float(x) for x in levels.split(",")]
    except ValueError:
        raise ValueError(f"--levels {levels!r}: expected wear levels in %, comma-separated, e.g. 1,5,10,15") from None
    if not all(0 < w <= 100 * 5 for w in wear_levels):  # faultgen.operation.wear.MAX_INCREASE
        raise ValueError(f"--levels {levels!r}: each level must be within 0..500 %")
    return wear_levels


def training_input(train: Path) -> None:
    """Refuse a ``--train`` dataset that fails validation, before any analysis runs."""
    from faultgen.data import dataset

    problems = dataset.validate(train)
    if problems:
        raise ValueError(f"--train {train} fails validation (run `faultgen validate {train}`): {problems[0]}")


#: bench-isolators' options.
SpeedWindow = Annotated[str | None, typer.Option(
    metavar="LOW,HIGH",
    help="Average |motor torque| only over samples whose motor speed lies in LOW..HIGH rad/s (thesis ch. "
         "6.3.2: 50,120); axes that leave the window empty in some cycle keep the whole-cycle mean. Prints "
         "how the window covers each task's motor speeds.")]
IsolatorPlugins = Annotated[list[str] | None, typer.Option(
    "--isolator", metavar="MODULE:CLASS",
    help="Also run your own isolator, a scikit-learn estimator setting source_axis_ in fit(X) (see "
         "analysis.isolation), e.g. mine:MyIsolator for class MyIsolator in mine.py in the current folder; "
         "repeat for several. The module is imported and so runs as code: name only modules you trust "
         "(docs/reliability.md, \"Threat model\"); one that fails or breaks the contract is refused, named.")]
TrainBaselineCycles = Annotated[int, typer.Option(help="With --train: the first cycles of each unit its signal is "
                                                      "centred and scaled by (pca_contribution's reference cycles).",
                                                 min=2)]


@app.command("bench-isolators", cls=Command)
def bench_isolators_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset with runs that wear one axis.")],
    bins: Annotated[list[int] | None, typer.Option("--bins", help="Transfer-entropy bin counts; repeat. Default 5 and 10.", min=2, max=100)] = None,
    levels: Annotated[str, typer.Option(help="Wear levels in %, comma-separated (thesis Table 6.2).")] = "1,5,10,15",
    speed_window: SpeedWindow = None,
    plugins: IsolatorPlugins = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-isolation').")] = None,
    overwrite: Overwrite = False,
    progress: Progress = True,
    train: Train = None,
    baseline: TrainBaselineCycles = 20,
) -> None:
    """Accuracy of every registered isolator (`faultgen bench baselines`: transfer entropy,
    cross-correlation, Granger, ...) at finding the worn axis, per task and wear level: CSV, Markdown (thesis Table 6.2 layout) and a PNG heatmap.

    Examples (the thesis's Table 6.2 on its grid; then averaging only over the motor speeds of
    thesis ch. 6.3.2; then with your own isolator, mine.py of docs/analysis.md):

    \b
      faultgen sweep --preset j2 -o j2.h5 && faultgen bench-isolators j2.h5
      faultgen bench-isolators j2.h5 --speed-window 50,120 -o j2-window
      faultgen bench-isolators j2.h5 --isolator mine:LargestRise -o j2-mine
    """
    from analysis import benchmark
    from analysis import plugins as plugins_

    wear_levels = parse_levels(levels)
    stem = out or file.with_name(file.stem + "-isolation")
    confusion_stem = stem.with_name(stem.name + "-confusion")
    written = [stem.with_suffix(".csv"), stem.with_suffix(".md"), stem.with_suffix(".png"),
               confusion_stem.with_suffix(".csv"), confusion_stem.with_suffix(".png")]
    analysis_input(file, written, overwrite)
    window = parse_window(speed_window) if speed_window is not None else None
    isolators = baselines.isolators(bins or (5, 10))  # every registered isolator (faultgen.bench.baselines)
    isolators.update({spec.rpartition(":")[2]: plugins_.load(spec, "isolator") for spec in plugins or []})
    stated = "protocol: own history (each isolator reads the tested run's own cycles)"
    if train is not None:
        from analysis import crossdata

        training_input(train)
        isolators, stated = crossdata.trained_isolators(isolators, train, file, baseline=baseline)
        stated = "protocol: " + stated
    table = benchmark.isolation_table(file, isolators, wear_levels, progress=progress, speed_window=window)
    typer.echo(stated)  # after the isolators ran: a plug-in refused in fit is the only line printed
    with atomic.output_set(written) as staged:  # all five outputs, or none
        benchmark.write_outputs(benchmark.isolation_csv(table), staged(stem), benchmark.isolation_markdown(table))
        benchmark.isolation_heatmap(table, staged(stem.with_suffix(".png")))
        confusion = benchmark.isolation_confusion(table)
        csv_cells.escaped(confusion).to_csv(staged(confusion_stem.with_suffix(".csv")))
        benchmark.confusion_figure(confusion, staged(confusion_stem.with_suffix(".png")))
    typer.echo(benchmark.isolation_report(table, file, window))
    typer.echo("wrote " + ", ".join(map(str, written)))


#: detect's options.
DetectProtocol = Annotated[str, typer.Option(
    help="Where the monitor learns normal operation: other-seeds (runs without wear of the other seeds: other "
         "units), first-cycles (the first --first samples of the tested run: its first days, thesis ch. 4), "
         "same-run (the run without wear of the same seed: thesis ch. 3, optimistic) or auto (on a fleet "
         "first-cycles, each robot its own first days; on a sweep other-seeds where the dataset has several "
         "seeds, else first-cycles where runs are longer than --first, else same-run). The protocol used and "
         "why is printed.")]
FirstSamples = Annotated[int | None, typer.Option(
    help="Samples the first-cycles protocol learns from. Default: 20, or the first half of a run of 20 samples "
         "or fewer (a 20-day fleet learns its first 10 days).", min=1, max=MAX_SAMPLES, show_default=False)]
DetectVariance = Annotated[float, typer.Option(help="Explained variance that sets the PCA components (thesis: 0.75).", min=0.0, max=1.0)]
DetectLimitFolds = Annotated[int, typer.Option(
    help="Folds over which the Q limit is estimated out of sample under other-seeds and first-cycles: a limit "
         "from the training samples alone (0; the thesis's eq. 2.6) alarms on more than ALPHA of new healthy "
         "data (j2, three seeds: 9.0 % at 5 %; 20 folds: 6.2 %). same-run always uses the thesis's limit.", min=0, max=MAX_FOLDS)]
Persistence = Annotated[
    int, typer.Option(help="Samples in a row above the limit to call an onset. 1 is the thesis's rule, but a 95 % "
                      "limit is then crossed by 5 % of normal samples, so long runs always alarm early.", min=1, max=MAX_SAMPLES)
]
Period = Annotated[int | None, typer.Option(help="Average the histograms of each PERIOD cycles into one sample (60: hours of one-minute cycles, c2).", min=1, max=MAX_CYCLES)]
DetectorPlugin = Annotated[str | None, typer.Option(
    "--detector", metavar="MODULE:CLASS",
    help="Your own detector instead of the PCA monitor: a scikit-learn estimator whose fit(X) learns healthy "
         "samples and whose predict(X) gives one alarm per sample, e.g. mine:MyDetector (mine.py in the "
         "current folder). The module is imported and so runs as code: name only modules you trust "
         "(docs/reliability.md, \"Threat model\"); one that fails or breaks the contract is refused, named.")]
DetectLocate = Annotated[str, typer.Option(
    help="How a detected onset is located: cross-correlation (the axis whose features lead all others', thesis "
         "ch. 3.4.2; it needs the fault to travel from the worn axis to the others) or contribution (the axis with "
         "the largest reconstruction-based contribution to the PCA monitor's Q and T2 at the alarm; the PCA monitor "
         "only). The share located is printed against chance.")]
DetectorBaseline = Annotated[str | None, typer.Option(
    help=f"A named detector instead of the PCA monitor: {', '.join(baselines.healthy_detectors())} (`faultgen "
         "bench baselines`; the classifiers learn labels, so only `bench score` takes them). --variance and "
         "--alpha are then unused.")]


@app.command("detect", cls=Command)
def detect_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset with worn runs and runs without wear.")],
    protocol: DetectProtocol = "auto",
    first: FirstSamples = None,
    variance: DetectVariance = 0.75,
    alpha: QAlpha = 0.05,
    limit_folds: DetectLimitFolds = 20,
    persistence: Persistence = 3,
    period: Period = None,
    locate: DetectLocate = "cross-correlation",
    plugin: DetectorPlugin = None,
    baseline: DetectorBaseline = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-detection').")] = None,
    overwrite: Overwrite = False,
    progress: Progress = True,
    train: Train = None,
) -> None:
    """PCA onset detection (Q statistic) and location per worn run, thesis Table 3.5 layout, with the
    false-alarm rate on healthy runs; summary per task and axis. No detection is counted before the
    fault begins: alarms before it are false alarms (column alarms_before_fault_pct).

    Writes OUT.csv and OUT.md (per run), OUT-summary.csv (per task, per worn axis, all) and OUT.png
    (the Q and T2 charts of each worn run with their limits, the fault's start and the onset).
    The summary leaves out runs whose monitor learned the fault as normal (trained_on_fault,
    column left_out); notes under it say what else the numbers rest on: a held-out false-alarm
    rate above alpha by more than its 95 % interval, why nothing was located, and advice the
    dataset can follow.

    Example:

    \b
      faultgen detect quick.h5
      faultgen fleet --robots 8 --days 20 -o fleet8.h5 && faultgen detect fleet8.h5
      faultgen sweep --preset quick --seed 0 --seed 1 -o quick-seeds.h5
      faultgen detect quick-seeds.h5 --protocol other-seeds -o quick-seeds-detection
      faultgen detect quick.h5 --baseline pca -o quick-pca     # iforest, ecod: the bench extra (pyod)
    """
    from analysis import benchmark
    from analysis import plugins as plugins_

    if plugin and baseline:
        raise ValueError("give one of --detector MODULE:CLASS or --baseline NAME")
    stem = out or file.with_name(file.stem + "-detection")
    summary_csv = stem.with_name(stem.name + "-summary.csv")
    written = [stem.with_suffix(".csv"), stem.with_suffix(".md"), stem.with_suffix(".png"), summary_csv]
    analysis_input(file, written, overwrite)
    detector = (plugins_.load(plugin, "detector") if plugin else
                baselines.healthy_detector(baseline) if baseline else None)
    if train is not None:  # another dataset learns normal operation (analysis.crossdata)
        from analysis import crossdata

        if protocol != "auto" or period is not None or locate != "cross-correlation":
            raise ValueError("--train sets the protocol (another dataset, each unit referred to its own first --first "
                             "records) and locates by cross-correlation; drop --protocol, --period and --locate")
        training_input(train)
        table, charts = crossdata.detection_across(
            file, train, first=first, variance=variance, alpha=alpha, persistence=persistence,
            limit_folds=limit_folds or None, detector=detector, progress=progress)
    else:
        table, charts = benchmark.detection_table(
            file, variance=variance, alpha=alpha, persistence=persistence, period=period, progress=progress,
            detector=detector, protocol=protocol, first=first, limit_folds=limit_folds or None, return_charts=True,
            locate=locate)
    for used, reason in table.attrs.get("protocol_reasons", {}).items():
        typer.echo(f"protocol auto -> {used}: {reason}")
    summary = benchmark.detection_summary(table)
    with atomic.output_set(written) as staged:  # all four outputs, or none
        benchmark.write_outputs(table, staged(stem))
        csv_cells.escaped(summary).to_csv(staged(summary_csv))
        benchmark.detection_figure(charts, staged(stem.with_suffix(".png")))
    typer.echo(benchmark.detection_text(table, summary, protocol))
    typer.echo("wrote " + ", ".join(map(str, written)))


#: training-source's option.
StudyLimitFolds = Annotated[int, typer.Option(
    help="Folds over which the Q limit is estimated out of sample; 0: from the training days alone, the "
         "thesis's eq. 2.6, which alarms on most test days of normal robots when the features are nearly as "
         "many as the training days.", min=0, max=MAX_FOLDS)]


@app.command("training-source", cls=Command)
def training_source_command(
    file: Annotated[Path, typer.Argument(help="A fleet (`faultgen fleet`): daily records of failing and normal robots.")],
    training_days: Annotated[int, typer.Option(help="Days each PCA model learns (thesis ch. 4.3.2: 40).", min=2, max=MAX_DAYS)] = 40,
    test_days: Annotated[int, typer.Option(help="Days tested after them (thesis: 15).", min=1, max=MAX_DAYS)] = 15,
    gap_days: Annotated[int, typer.Option(help="Last days left out, the failure day included (thesis: 5).", min=0, max=MAX_DAYS)] = 5,
    variance: Annotated[float, typer.Option(help="Explained variance that sets the PCA components (thesis: 0.90).", min=0.0, max=1.0)] = 0.90,
    alpha: QAlpha = 0.05,
    limit_folds: StudyLimitFolds = 20,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-training-source').")] = None,
    overwrite: Overwrite = False,
    progress: Progress = True,
    train: Train = None,
) -> None:
    """The training-source study of thesis chapter 4 (Table 4.1) on a fleet. Each robot is tested on its
    test days by a PCA model learnt from its own first days (one-to-one, OTO) or from those of
    each normal robot of its model (one-to-many, OTM), on raw, absolute-difference and combined
    signals; the Q residual's coefficient of variation, samples above the limit and lead time
    are compared by a three-way ANOVA and Tukey's HSD (Tables 4.2-4.4, Figs. 4-4 to 4-6).

    Writes OUT-cases.csv (one row per test case), OUT-anova.csv, OUT-tukey.csv, OUT.md, OUT.png.

    Example:

    \b
      faultgen fleet -o fleet.h5 && faultgen training-source fleet.h5 -o fleet-ch4
    """
    from analysis import training_source as ts

    stem = out or file.with_name(file.stem + "-training-source")
    paths = {name: stem.with_name(stem.name + suffix) for name, suffix in
             (("cases", "-cases.csv"), ("anova", "-anova.csv"), ("tukey", "-tukey.csv"), ("md", ".md"),
              ("png", ".png"))}
    analysis_input(file, list(paths.values()), overwrite)
    if train is not None:
        training_input(train)
    window = ts.Window(training_days, test_days, gap_days)
    cases = ts.study(file, window, variance=variance, alpha=alpha, limit_folds=limit_folds or None,
                     progress=progress, train=train)
    text, anova, tukey = ts.report(cases, train)
    if tukey is None:  # an empty cell: the cases and means stand, the tests cannot be run
        del paths["anova"], paths["tukey"]
    with atomic.output_set(paths.values()) as staged:  # all outputs, or none
        if tukey is not None:
            csv_cells.escaped(anova).to_csv(staged(paths["anova"]), index=False)
            csv_cells.escaped(tukey).to_csv(staged(paths["tukey"]), index=False)
        csv_cells.escaped(cases).to_csv(staged(paths["cases"]), index=False)
        staged(paths["md"]).write_text(text + "\n")
        ts.figure(cases, staged(paths["png"]), marked=tukey)
    typer.echo(text)
    typer.echo("wrote " + ", ".join(map(str, paths.values())))


#: classify's options.
WearThreshold = Annotated[float, typer.Option(help="A cycle is 'failed' when its true wear is at least this, %.", min=0.0, max=500.0)]
Pairs = Annotated[int, typer.Option(help="Worn/unworn run pairs left out (Procedure 1); 0 = all (refused when there are more than 100000).", min=0, max=MAX_PAIRS)]
Horizon = Annotated[int | None, typer.Option(
    help="The thesis's protocol (ch. 5.3.3): keep each run's samples from HORIZON + 10 to HORIZON before its "
    "last (T-13 to T-3 for 3; T the failure day of a failing robot), labelled by the robot's state, failing or "
    "healthy, instead of by --wear-threshold. Table 5.2 used 3.", min=0, max=MAX_DAYS)]
MatchedDays = Annotated[bool, typer.Option(
    "--matched-days", help="A time control: rank a failing run's failed samples only against the healthy run's "
    "samples at the same positions in its record (same day of the record), not against earlier days. Labels by "
    "wear put a failing robot's failed days last, so whatever drifts along a record (season, the indicators "
    "settling) scores without any fault; matched it cannot. No change with --horizon.")]
Permutations = Annotated[int, typer.Option(
    help="Also the chance level of each cell on these robots: the AUC again with the runs' labels exchanged "
    "this many times (columns 'null', their mean, and 'p', the permutation p-value of the AUC). Each costs as "
    "much as the table: choose cells with --classifier/--preprocessing. 0 = none.", min=0, max=MAX_PERMUTATIONS)]
Classifiers = Annotated[list[str] | None, typer.Option(
    "--classifier", help="Only this classifier (lr, svm, rf, stacking); repeat for several. Default all.")]
Preprocessings = Annotated[list[str] | None, typer.Option(
    "--preprocessing", help="Only this row of Table 5.2 (control, +diff, +estM+diff+var3+pca, ...); repeat for "
    "several. Default: see --full.")]
FullTable = Annotated[bool, typer.Option(
    "--full", help="Every row: Table 5.2's fifteen and four more (+var5, +diff+var3, +diff+var5+pca, "
    "+estM+diff+var5+pca), 2 to 3 times the time. Default seven rows, each step alone and the fullest "
    "combinations: control, +estM, +diff, +pca, +var3, +diff+var3+pca, +estM+diff+var3+pca.")]
ClassifySeed = Annotated[int, typer.Option(help="Seed for the choice of pairs, the permutations and the random forest.", min=0, max=MAX_SEED)]
Chance = Annotated[bool, typer.Option(
    help="Without --permutations, measure each row's chance level on lr (19 label exchanges, about half the "
    "default table's time again) and judge every cell against it: columns chance, p and above_chance, and a "
    "verdict line. --no-chance: not measured, no verdict.")]
PairJobs = Annotated[int, typer.Option(help="Held-out pairs fitted in parallel (processes); 0: one per core.", min=0, max=1024)]
TrainBaselineRecords = Annotated[int, typer.Option(help="With --train: the first records of each unit its features "
                                                       "are centred and scaled by.", min=2)]


@app.command("classify", cls=Command)
def classify_command(
    file: Annotated[Path, typer.Argument(help="A faultgen dataset with worn runs and runs without wear.")],
    wear_threshold: WearThreshold = 10.0,
    pairs: Pairs = 20,
    horizon: Horizon = None,
    matched_days: MatchedDays = False,
    permutations: Permutations = 0,
    classifiers: Classifiers = None,
    preprocessing: Preprocessings = None,
    full: FullTable = False,
    seed: ClassifySeed = 0,
    chance: Chance = True,
    jobs: PairJobs = 0,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Output stem (default: FILE without .h5 + '-classification').")] = None,
    overwrite: Overwrite = False,
    progress: Progress = True,
    train: Train = None,
    baseline: TrainBaselineRecords = 5,
) -> None:
    """AUC of LR, SVM, RF and stacking per preprocessing combination, thesis Table 5.2 layout.

    Writes OUT.csv (tidy: one row per cell), OUT.md (the table with its caption) and OUT.png (a
    heatmap coloured around the chance level).

    A sample is a recorded cycle (a day in a fleet). Its features per axis are those of thesis
    Table 5.1: the speed and torque indicators (the axis's average speed and mean load over its
    production so far) and the KL divergences of its angle, speed and torque histograms against
    the run's first sample; the "+estM" rows add each sample's own average speed and load. A
    sample is 'failed' when its true wear reaches --wear-threshold. Procedure 1 holds out one
    worn and one unworn run at a time, trains on the rest and scores the pair by AUC; --pairs 0
    takes every pair, as the thesis did.

    Robots of one kind (process, model) look alike, so chance is not 0.5 here: by default each
    row's chance level is measured on lr with the runs' labels exchanged, every cell gets its
    permutation p-value and above_chance (p <= 0.05), and a verdict line says whether any cell
    beats chance; --permutations measures the chance level of every cell instead. With labels by wear a
    failing robot's failed days are its last, so a classifier that only learns when in the record
    a day lies scores well above 0.5; --matched-days compares them with the same days of the
    healthy robot instead.

    By default seven rows of Table 5.2 are computed (each step alone and the fullest
    combinations); --full computes every row, the thesis's fifteen and four more, in 2 to 3 times
    the time.

    Examples (the thesis's protocol: its window before failure, every pair; the same with every
    row of Table 5.2; then the chance level of two cells on labels by wear; then of one with the
    time control):

    \b
      faultgen fleet -o fleet.h5 && faultgen classify fleet.h5 --horizon 3 --pairs 0
      faultgen classify fleet.h5 --horizon 3 --pairs 0 --full -o fleet-full
      faultgen classify fleet.h5 --classifier lr --preprocessing control --preprocessing +diff --permutations 19 -o fleet-lr
      faultgen classify fleet.h5 --matched-days --classifier lr --preprocessing +diff --permutations 19 -o fleet-matched
    """
    from analysis import benchmark

    stem = out or file.with_name(file.stem + "-classification")
    written = [stem.with_suffix(s) for s in (".csv", ".md", ".png")]
    analysis_input(file, written, overwrite)
    if train is not None:  # fitted on another dataset, scored on FILE (analysis.crossdata)
        classify_on_other(file, train, stem, wear_threshold, baseline, seed, progress, permutations, classifiers,
                          preprocessing, horizon, matched_days)
        return
    cells = {k: v for k, v in (("classifiers", classifiers), ("preprocessing", preprocessing)) if v}
    table = benchmark.classification_table(
        file, wear_threshold=wear_threshold, n_pairs=pairs or None, random_state=seed, progress=progress,
        horizon=horizon, permutations=permutations, matched=matched_days, chance=chance, n_jobs=jobs or -1,
        short=not full, **cells)
    text = benchmark.classification_text(table, file, pairs=pairs, horizon=horizon, wear_threshold=wear_threshold,
                                         matched=matched_days, full=full, **cells)
    with atomic.output_set(written) as staged:  # all, or none
        csv_cells.escaped(benchmark.classification_tidy(table)).to_csv(staged(stem.with_suffix(".csv")), index=False)
        staged(stem.with_suffix(".md")).write_text(text + "\n")
        benchmark.classification_heatmap(table, staged(stem.with_suffix(".png")))
    typer.echo(text)
    typer.echo(f"protocol: units of {file} itself (each pair of held-out runs scored by a model of the others; "
               "--train OTHER.h5 learns from another dataset)")
    typer.echo("wrote " + ", ".join(map(str, written)))


def classify_on_other(file: Path, train: Path, stem: Path, wear_threshold: float, baseline: int, seed: int,
                      progress: bool, permutations: int, classifiers: list[str] | None,
                      preprocessing: list[str] | None, horizon: int | None, matched_days: bool) -> None:
    """``classify --train OTHER``: the classifiers fitted on ``train``, scored on ``file``'s samples
    labelled by ``wear_threshold`` (:func:`analysis.crossdata.classification_across`); writes
    STEM.csv and STEM.md.

    Raises
    ------
    ValueError
        With ``horizon`` or ``matched_days`` (another protocol), or a ``train`` that fails validation.
    """
    from analysis import benchmark, crossdata

    if horizon is not None or matched_days:
        raise ValueError("--train labels FILE's samples by --wear-threshold; drop --horizon and --matched-days")
    training_input(train)
    table = crossdata.classification_across(
        file, train, wear_threshold=wear_threshold, baseline=baseline, random_state=seed, progress=progress,
        permutations=permutations or 19, **({"classifiers": classifiers} if classifiers else {}),
        preprocessing=preprocessing or None)
    text = benchmark.classification_across_text(table, file, train)
    csv_cells.escaped(table).to_csv(stem.with_suffix(".csv"))
    stem.with_suffix(".md").write_text(text + "\n")
    typer.echo(text)
    typer.echo("wrote " + ", ".join(str(stem.with_suffix(s)) for s in (".csv", ".md")))
