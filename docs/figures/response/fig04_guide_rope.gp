# Fig. 4: lateral displacement of guide rope 1 (rope 2 dashed)
# Written by hoist-study; re-render with:  cd docs/figures/response && gnuplot fig04_guide_rope.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig04_guide_rope.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 1,1 title 'Fig. 4: lateral displacement of guide rope 1 (rope 2 dashed)'
set xlabel 'depth x [m]'
set ylabel 'y [mm]'
plot 'shapes.csv' using "x":(column("t")==18?column("y1")*1e3:NaN) with lines lc 1 title 't = 18 s', \
     'shapes.csv' using "x":(column("t")==18?column("y2")*1e3:NaN) with lines dt 2 lc 1 title '', \
     'shapes.csv' using "x":(column("t")==36?column("y1")*1e3:NaN) with lines lc 2 title 't = 36 s', \
     'shapes.csv' using "x":(column("t")==36?column("y2")*1e3:NaN) with lines dt 2 lc 2 title '', \
     'shapes.csv' using "x":(column("t")==60?column("y1")*1e3:NaN) with lines lc 3 title 't = 60 s', \
     'shapes.csv' using "x":(column("t")==60?column("y2")*1e3:NaN) with lines dt 2 lc 3 title ''
unset multiplot
