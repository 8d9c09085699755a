# Fig. 13: constraint force lambda_1 vs cage mass
# Written by hoist-study; re-render with:  cd docs/figures/mass && gnuplot fig13_lambda1.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig13_lambda1.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 1,1 title 'Fig. 13: constraint force lambda_1 vs cage mass'
set xlabel 't [s]'
set ylabel 'lambda_1 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_1")*1) with lines title 'm=800 kg, J=870', \
     'runs/run2.csv' using "t":(column("lambda_1")*1) with lines title 'm=1200 kg, J=1305', \
     'runs/run3.csv' using "t":(column("lambda_1")*1) with lines title 'm=1600 kg, J=1740'
unset multiplot
