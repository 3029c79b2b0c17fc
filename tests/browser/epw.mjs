// A synthetic EPW for the browser tests: a whole year whose direct normal irradiance varies from
// hour to hour (so that a year's irradiation weighs its timesteps differently), at the site a
// LOCATION line names.

export const GOLDEN = 'LOCATION,Golden,CO,USA,test,724666,39.74,-105.18,-7.0,1829';
export const SYDNEY = 'LOCATION,Sydney,NSW,AUS,test,947670,-33.87,151.21,10.0,39';

/** The EPW's text for the site of `location` (a LOCATION line). */
export function syntheticEpw(location) {
  const lines = [location, 'DESIGN CONDITIONS,0', 'TYPICAL/EXTREME PERIODS,0',
    'GROUND TEMPERATURES,0', 'HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0', 'COMMENTS 1,', 'COMMENTS 2,', 'DATA PERIODS,1,1,Data,Sunday,1/1,12/31'];
  const days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31];
  let n = 0;
  days.forEach((count, m) => {
    for (let d = 1; d <= count; d++) {
      for (let h = 1; h <= 24; h++) {
        const dni = 200 + ((n++ * 37) % 600);
        lines.push(`1999,${m + 1},${d},${h},60,x,20,10,50,101000,0,1300,300,500,${dni},100,0,0,0,0,0,0,0,0,0,0,9,0,0,0,0,0,0,0,0`);
      }
    }
  });
  return `${lines.join('\n')}\n`;
}
