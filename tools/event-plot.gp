# The event picture (tools/plinth-event-plot runs this in a private folder): trace.tsv (one line
# per sample, plinth-monitor --trace) and marks.tsv (time, label: the collapse or the all-clear)
# into event.png. Variables from the caller, numbers only and a plain title: t_min, t_max,
# g_max (g), th_max (deg), axes (1 or 2), advisory_on, warning_on, alarm_on, title_text.
set terminal pngcairo size 1100,1000 font "DejaVu Sans,11" noenhanced
set output "event.png"
set datafile separator "\t"
set datafile commentschars "#"
set multiplot layout 4,1 title title_text font ",13"
set lmargin at screen 0.10
set rmargin at screen 0.88
set xrange [t_min:t_max]
set grid xtics ytics lc rgb "#dddddd"
set key top left opaque box lc rgb "#bbbbbb"
deg = 180.0 / pi
g0 = 9.80665
set style line 9 lc rgb "#c00000" dt 2 lw 2

# 1. Ground acceleration.
set ylabel "ground acceleration (g)"
set yrange [-g_max:g_max]
set format x ""
plot "trace.tsv" using 1:($5 / g0) with lines lc rgb "#1f77b4" title "x", \
     "trace.tsv" using 1:(axes > 1 ? $8 / g0 : NaN) with lines \
         lc rgb "#ff7f0e" title (axes > 1 ? "y" : ""), \
     "marks.tsv" using 1:(-g_max):(0):(2 * g_max) with vectors nohead ls 9 notitle

# 2. The block's rotation and its phase.
set ylabel "rotation (deg)"
set yrange [-th_max:th_max]
set y2label "phase"
set y2range [-0.5:6.5]
set y2tics ("full contact" 0, "sliding" 1, "rocking" 2, "slide-rocking" 3, "overturned" 4, \
            "fell" 5, "lifted off" 6)
set ytics nomirror
plot "trace.tsv" using 1:($6 * deg) with lines lc rgb "#1f77b4" lw 2 title "rotation x", \
     "trace.tsv" using 1:(axes > 1 ? $9 * deg : NaN) with lines lc rgb "#ff7f0e" lw 2 \
         title (axes > 1 ? "rotation y" : ""), \
     "trace.tsv" using 1:7 axes x1y2 with steps lc rgb "#2ca02c" title "phase x", \
     "trace.tsv" using 1:(axes > 1 ? $10 : NaN) axes x1y2 with steps lc rgb "#9467bd" \
         title (axes > 1 ? "phase y" : ""), \
     "marks.tsv" using 1:(-th_max):(0):(2 * th_max) with vectors nohead ls 9 notitle
unset y2tics
unset y2label
set ytics mirror

# 3. The overturning risk against the alarm policy's thresholds.
set ylabel "risk (0 rest, 1 collapse)"
set yrange [0:1.05]
plot "trace.tsv" using 1:2 with lines lc rgb "#000000" lw 2 title "risk", \
     advisory_on with lines lc rgb "#e6b800" dt 2 lw 1.5 title "advisory threshold", \
     warning_on with lines lc rgb "#ff7f0e" dt 2 lw 1.5 title "warning threshold", \
     alarm_on with lines lc rgb "#d62728" dt 2 lw 1.5 title "alarm threshold", \
     "marks.tsv" using 1:(0):(0):(1.05) with vectors nohead ls 9 notitle

# 4. The alarm levels, and the marks' labels.
set ylabel "alarm level"
set yrange [-0.4:4.6]
set ytics ("normal" 0, "advisory" 1, "warning" 2, "alarm" 3, "fault" 4)
set format x "%g"
set xlabel "time in the capture (s)"
set key bottom right
plot "trace.tsv" using 1:3 with steps lc rgb "#d62728" lw 3 title "shown", \
     "trace.tsv" using 1:4 with steps lc rgb "#555555" dt 2 lw 2 title "latched (until acknowledged)", \
     "marks.tsv" using 1:(-0.4):(0):(5.0) with vectors nohead ls 9 notitle, \
     "marks.tsv" using 1:(4.25):2 with labels left offset 0.7,0 tc rgb "#c00000" notitle
unset multiplot
