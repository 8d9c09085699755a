# preload advisor: peak cage excursion and sleeve force vs total preload
# Written by hoist-study; re-render with:  cd docs/figures/advise && gnuplot advise.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,650 font ',9' linewidth 1.2
} else {
  set terminal png size 800,650
}
set termoption noenhanced
set output 'advise.png'
set datafile separator ','
set grid
set key inside top right samplen 2
set multiplot layout 2,1 title 'preload advisor: peak cage excursion and sleeve force vs total preload'
set xlabel 'total preload Tb1 + Tb2 [kN]'
set ylabel 'peak excursion [mm]'
set logscale xy
plot 'advise_curve.csv' using (column("total")/1e3):(column("peak_excursion")*1e3) with linespoints pt 7 ps 0.6 title 'max |y_c -+ h theta| (split 0.5)', \
     'advise_curve.csv' using (column("total")/1e3):(8) with lines dt 2 lc rgb 'red' title 'clearance', \
     'advise_recommended.csv' using (column("total")/1e3):(column("peak_excursion")*1e3) with points pt 9 ps 1.5 lc rgb 'dark-green' title 'recommended'
unset logscale; unset arrow; unset label; set autoscale
set xlabel 'total preload Tb1 + Tb2 [kN]'
set ylabel 'peak |lambda_1..4| [N]'
set logscale x
plot 'advise_curve.csv' using (column("total")/1e3):"peak_sleeve_force" with linespoints pt 7 ps 0.6 title 'peak sleeve force'
unset logscale; unset arrow; unset label; set autoscale
unset multiplot
